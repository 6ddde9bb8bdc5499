// Opening an input file (scene, mesh, glTF buffer) safely: only regular files are read, checked
// on the open descriptor (a FIFO, a character device such as /dev/zero or /dev/stdin, a socket
// or a folder is refused before a byte is read, and never blocks: the open is non-blocking), the
// size is checked against a limit before anything is allocated, and folder confinement is
// decided on resolved paths (symlinks and ".." followed first).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "pipeline/input/status.h"

namespace apparent {

// Reads all of regular file `path` (symlinks followed) into `out`, at most `max_bytes` bytes.
// Fails with one line starting with `path`: "cannot open WHAT: reason" (`what`: "mesh file",
// "scene file"), "is a FIFO, not a regular file (refused)", "N bytes, larger than the limit of M
// bytes (raise with --max-file-bytes)".
Status readRegularFile(const std::string& path, size_t max_bytes, std::string* out, const char* what = "file");

// The same checks, the file left open for reading: its descriptor (the caller closes it) and size.
Status openRegularFile(const std::string& path, int* fd, uint64_t* size, const char* what = "file");

// The same checks without reading: `path` resolves to an existing regular file.
Status checkRegularFile(const std::string& path);

// True when `path` resolves (std::filesystem::weakly_canonical: symlinks and ".." followed) to
// `root` or below it; `root` is resolved the same way. Compared component by component, so
// "/a/bc" is not inside "/a/b".
bool resolvesInside(const std::string& path, const std::string& root);

}  // namespace apparent
