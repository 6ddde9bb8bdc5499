// Frame data by reference (frames across processes, pipeline/run/distribute.h): instead of sending a
// frame's binary data to the writing process, the process that cut the frame writes it to a file
// of its own, its frame spill, and sends only where it lies (FileSpan). The writing process reads
// those files through the table of frame sources and copies the pieces into the output with
// copy_file_range (the kernel copies; no user buffer), or has their processes copy them into it
// (placeFrameData). One spill per process, shared by every
// sink and sequence of the run; source ids are the processes' ranks.
// - encode side: installFrameSpill(fd, source) once; then spillFrameData() from any thread: each
//   call reserves its range with one atomic add and writes it with pwritev, so frames cut at once
//   write side by side without a lock.
// - writing side: addFrameSource(source, fd) for every process (its own included); frameSource()
//   finds the file; releaseFrameData() gives a range back (a hole punched) once it is copied.
// The files are opened by name once at the start and unlinked at once (pipeline/run/distribute.cpp):
// nothing is left behind afterwards, whatever ends the processes. Every process must see the
// others' files: a file system all ranks share (Lustre, GPFS, NFS with close-to-open: rank 0
// opens them after the writes that it reads, as the frames' messages order them).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <sys/uio.h>
#include <vector>

namespace apparent {

// A range of a frame source's file: `length` bytes at `offset` of source `source`.
struct FileSpan {
    int32_t source = -1;
    uint64_t offset = 0;
    uint64_t length = 0;
};

// The encode side: this process's spill `fd` (kept open until the process ends), known to the
// writer as source `source`.
void installFrameSpill(int fd, int source);
bool frameSpillInstalled();
// Whether meshopt frames that may be morph targets also travel by reference (default true): then
// each process cuts the frame before each of its frames again and encodes both forms
// (GlbSink::encodesAfterPrevious), about 2.5 times a process's work per frame for rank 0's 0.1 times;
// false: such frames travel whole to rank 0 (docs/PERFORMANCE.md, "Meshopt morph targets by
// reference"). pipeline/run/distribute.cpp sets it from the number of processes.
void setMorphTargetsByReference(bool on);
bool morphTargetsByReference();
// The run's random token (the same on every process, pipeline/run/distribute.h): names of files the
// processes make for one another in the output folder carry it (exporters/frame_files.h).
void setFrameRunToken(const std::string& token);
const std::string& frameRunToken();
// Writes the pieces one after another at a fresh range of the spill and returns one span per
// piece (contiguous); false with errno's message when the write fails.
bool spillFrameData(const std::vector<iovec>& pieces, std::vector<FileSpan>* spans, std::string* error);

// Where a range of frame data goes in an output file: at byte `to`.
struct Placement {
    FileSpan from;
    uint64_t to = 0;
};
// Copies every placement from its source (this process's spill, or a file of the table below)
// into the file at `path`, opened by name and written at the offsets (copy_file_range; pread and
// pwrite where it cannot), then synced; false with the reason (errno's message).
bool placeHere(const std::string& path, const std::vector<Placement>& placements, std::string* error);
// How the writer places frame data at the end: placeHere() unless another placer is installed.
// Under MPI rank 0 installs one that has each rank copy its own frames' ranges, all at once
// (pipeline/run/distribute.h): rank 0 then writes only the file's head and its own frames.
using FramePlacer = std::function<bool(const std::string& path, const std::vector<Placement>& placements,
                                       std::string* error)>;
void setFramePlacer(FramePlacer placer);
bool placeFrameData(const std::string& path, const std::vector<Placement>& placements, std::string* error);

// The writing side: the file of source `source` (the table owns `fd`), -1 when not known.
void addFrameSource(int source, int fd);
int frameSource(int source);
// The range is copied into its output and read no more: its disk space is freed (best effort).
void releaseFrameData(const FileSpan& span);

}  // namespace apparent
