// scenes/json_unique_keys.hpp — JSON parsing that refuses duplicate keys, nesting deeper than
// kMaxJsonDepth and NUL bytes. nlohmann::json keeps the last of two equal keys in one object
// without a word, so a scene file or a magsolve case with "position" twice ran with whichever
// came last; its lexer takes a NUL byte for the end of the text, so a valid document followed
// by a NUL and junk was read as valid. The parser callback sees every key of every object; a
// stack of open objects and arrays, each holding only its own step of the JSON path, gives
// the path for an error (memory linear in the depth, not quadratic).
// Header-only: scene files (magsim_scenes) and magsolve (magnetics only) both use it.
#pragma once

#include <nlohmann/json.hpp>

#include <cstddef>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace magsim::scenes {

/// Objects and arrays nested deeper than this are refused: scene files and magsolve cases
/// need 6 levels, and each open level costs the parser a stack entry.
constexpr std::size_t kMaxJsonDepth = 64;

/// Thrown by parse_unique_keys for text that parses but breaks one of its rules; what() is
/// "<json path>: <what>", e.g. "bodies[0].position: duplicate key".
struct JsonStructureError : std::runtime_error {
  using std::runtime_error::runtime_error;
};
/// A key given twice in one object.
struct DuplicateKeyError : JsonStructureError {
  using JsonStructureError::JsonStructureError;
};

namespace detail {

/// `path` for a one-line message: at most about 200 bytes, the middle elided at UTF-8
/// character boundaries (a path through 64 levels of long keys could run to megabytes).
inline std::string short_json_path(const std::string& path) {
  constexpr std::size_t kHead = 80, kTail = 100;
  if (path.size() <= kHead + kTail + 20) return path;
  auto boundary = [&](std::size_t i) {  // back to the start of a UTF-8 character
    while (i > 0 && (static_cast<unsigned char>(path[i]) & 0xc0) == 0x80) --i;
    return i;
  };
  const std::size_t head = boundary(kHead), tail = boundary(path.size() - kTail);
  return path.substr(0, head) + " ... " + path.substr(tail);
}

}  // namespace detail

/// json::parse(text) that throws DuplicateKeyError for a key given twice in one object and
/// JsonStructureError for objects and arrays nested deeper than kMaxJsonDepth or a NUL byte
/// anywhere in the text (json::exception for malformed text, as json::parse).
inline nlohmann::json parse_unique_keys(const std::string& text, bool ignore_comments = false) {
  using json = nlohmann::json;
  if (const std::size_t nul = text.find('\0'); nul != std::string::npos)
    throw JsonStructureError("malformed JSON: a NUL byte at byte offset " + std::to_string(nul) +
                             " (JSON text has none; the parser would stop there)");
  struct Open {
    bool object;
    std::string step;            // how the parent reaches this value: "key", ".key" or "[i]"
    std::set<std::string> keys;  // object: keys seen so far
    std::string key;             // object: the key whose value comes next
    std::size_t count = 0;       // array: elements seen so far
  };
  std::vector<Open> stack;
  // the JSON path of the innermost open level, then `last` (built only for an error)
  auto path_to = [&stack](const std::string& last) {
    std::string p;
    for (const Open& o : stack) p += o.step;
    return detail::short_json_path(p + last);
  };
  // the path step of the value that starts now (and counts it as an array element)
  auto next_step = [&stack]() -> std::string {
    if (stack.empty()) return "";
    Open& top = stack.back();
    if (top.object) return stack.size() == 1 ? top.key : "." + top.key;
    return "[" + std::to_string(top.count++) + "]";
  };
  const json::parser_callback_t cb = [&](int, json::parse_event_t event, json& parsed) {
    switch (event) {
      case json::parse_event_t::object_start:
      case json::parse_event_t::array_start: {
        std::string step = next_step();
        if (stack.size() >= kMaxJsonDepth)
          throw JsonStructureError(path_to(step) + ": objects and arrays nested deeper than " +
                                   std::to_string(kMaxJsonDepth) + " levels");
        stack.push_back(Open{event == json::parse_event_t::object_start, std::move(step), {}, {}, 0});
        break;
      }
      case json::parse_event_t::object_end:
      case json::parse_event_t::array_end:
        if (!stack.empty()) stack.pop_back();
        break;
      case json::parse_event_t::key: {
        Open& top = stack.back();
        top.key = parsed.get<std::string>();
        if (!top.keys.insert(top.key).second)
          throw DuplicateKeyError(path_to((stack.size() == 1 ? "" : ".") + top.key) + ": duplicate key");
        break;
      }
      case json::parse_event_t::value:
        if (!stack.empty() && !stack.back().object) ++stack.back().count;
        break;
    }
    return true;
  };
  return json::parse(text, cb, /*allow_exceptions=*/true, ignore_comments);
}

}  // namespace magsim::scenes
