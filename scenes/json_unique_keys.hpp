// scenes/json_unique_keys.hpp — JSON parsing that refuses duplicate keys. nlohmann::json
// keeps the last of two equal keys in one object without a word, so a scene file or a
// magsolve case with "position" twice ran with whichever came last. The parser callback
// sees every key of every object; a stack of open objects and arrays gives the JSON path.
// Header-only: scene files (magsim_scenes) and magsolve (magnetics only) both use it.
#pragma once

#include <nlohmann/json.hpp>

#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace magsim::scenes {

/// Thrown by parse_unique_keys; what() is "<json path>: duplicate key", e.g.
/// "bodies[0].position: duplicate key".
struct DuplicateKeyError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// json::parse(text) that throws DuplicateKeyError for a key given twice in one object
/// (json::exception for malformed text, as json::parse).
inline nlohmann::json parse_unique_keys(const std::string& text, bool ignore_comments = false) {
  using json = nlohmann::json;
  struct Open {
    bool object;
    std::string path;            // of this object or array
    std::set<std::string> keys;  // object: keys seen so far
    std::string key;             // object: the key whose value comes next
    std::size_t count = 0;       // array: elements seen so far
  };
  std::vector<Open> stack;
  // the path of the value that starts now (and counts it as an array element)
  auto next_path = [&stack]() -> std::string {
    if (stack.empty()) return "";
    Open& top = stack.back();
    if (top.object) return top.path.empty() ? top.key : top.path + "." + top.key;
    return top.path + "[" + std::to_string(top.count++) + "]";
  };
  const json::parser_callback_t cb = [&](int, json::parse_event_t event, json& parsed) {
    switch (event) {
      case json::parse_event_t::object_start:
      case json::parse_event_t::array_start: {
        const std::string path = next_path();
        stack.push_back(Open{event == json::parse_event_t::object_start, path, {}, {}, 0});
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
          throw DuplicateKeyError((top.path.empty() ? top.key : top.path + "." + top.key) + ": duplicate key");
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
