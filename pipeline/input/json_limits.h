// Bounds on JSON text before any recursive code sees it, and JSON for messages.
//
// nlohmann's dump() and tinygltf's parser recurse once per nesting level, so a 200 KB array nested
// 100 000 deep overflows the stack. checkJsonDepth scans the text linearly (strings skipped,
// escapes honoured, comments too when allowed) and refuses nesting deeper than kMaxJsonDepth
// before anything parses it. Every scene file and every glTF JSON chunk (also a glTF scene's) is
// checked, so what is parsed afterwards is at most kMaxJsonDepth deep wherever it is printed.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "pipeline/input/status.h"

namespace apparent {

constexpr size_t kMaxJsonDepth = 128;  // glTF needs about 8 levels, scenes about 6; extras some more

// Fails with "FILE: JSON nested deeper than 128 levels at byte N (refused)" when arrays and objects
// of `text` nest deeper than `max_depth`. Brackets inside strings do not count; with
// `comments`, neither do those inside // and /* */ comments (nlohmann's ignore_comments).
Status checkJsonDepth(const std::string& file, std::string_view text, bool comments = false,
                      size_t max_depth = kMaxJsonDepth);

// `text` printable on one line: control characters as \n, \t, \u001b; bytes that are not valid
// UTF-8 as \xNN; cut to about `max_bytes` with "..." at the end.
std::string printable(std::string_view text, size_t max_bytes = 200);

// True when `text` is valid UTF-8 (what a JSON string, and a name written into a .glb, must be).
bool isValidUtf8(std::string_view text);

// A JSON value for a message: compact, invalid UTF-8 replaced, printable and cut to `max_bytes`.
std::string jsonForMessage(const nlohmann::json& value, size_t max_bytes = 40);

}  // namespace apparent
