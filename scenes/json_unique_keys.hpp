// scenes/json_unique_keys.hpp — JSON parsing that refuses duplicate keys, nesting deeper than
// kMaxJsonDepth and NUL bytes. nlohmann::json keeps the last of two equal keys in one object
// without a word, so a scene file or a magsolve case with "position" twice ran with whichever
// came last; its lexer takes a NUL byte for the end of the text, so a valid document followed
// by a NUL and junk was read as valid. A SAX handler sees every key of every object and builds
// the document with nlohmann's own DOM builder; a stack of open objects and arrays, each
// holding only its own step of the JSON path, gives the path for an error (memory linear in
// the depth, not quadratic; time linear in the text).
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

namespace detail {

/// nlohmann's DOM builder (json_sax_dom_parser: what json::parse uses, linear in the text)
/// with the rules of parse_unique_keys on top. Not the callback parser: after every object
/// or array it rescans the whole parent for values to discard, so a "bodies" array of N
/// objects took time in N^2 (160k bodies took 4.8 s, 10^6 bodies minutes).
class UniqueKeySax {
 public:
  using json = nlohmann::json;
  explicit UniqueKeySax(json& result) : dom_(result, /*allow_exceptions=*/true) {}

  bool null() { return element() && dom_.null(); }
  bool boolean(bool v) { return element() && dom_.boolean(v); }
  bool number_integer(json::number_integer_t v) { return element() && dom_.number_integer(v); }
  bool number_unsigned(json::number_unsigned_t v) { return element() && dom_.number_unsigned(v); }
  bool number_float(json::number_float_t v, const json::string_t& s) { return element() && dom_.number_float(v, s); }
  bool string(json::string_t& v) { return element() && dom_.string(v); }
  bool binary(json::binary_t& v) { return element() && dom_.binary(v); }
  bool start_object(std::size_t n) { return open(true) && dom_.start_object(n); }
  bool start_array(std::size_t n) { return open(false) && dom_.start_array(n); }
  bool end_object() {
    stack_.pop_back();
    return dom_.end_object();
  }
  bool end_array() {
    stack_.pop_back();
    return dom_.end_array();
  }
  bool key(json::string_t& k) {
    Open& top = stack_.back();
    if (!top.keys.insert(k).second) throw DuplicateKeyError(path_to((stack_.size() == 1 ? "" : ".") + k) + ": duplicate key");
    top.key = k;
    return dom_.key(k);
  }
  template <class Exception>
  bool parse_error(std::size_t pos, const std::string& token, const Exception& e) {
    return dom_.parse_error(pos, token, e);  // throws e
  }

 private:
  struct Open {
    bool object;
    std::string step;            // how the parent reaches this value: "key", ".key" or "[i]"
    std::set<std::string> keys;  // object: keys seen so far
    std::string key;             // object: the key whose value comes next
    std::size_t count = 0;       // array: elements seen so far
  };
  // a value starts: counted as its array's next element
  bool element() {
    if (!stack_.empty() && !stack_.back().object) ++stack_.back().count;
    return true;
  }
  bool open(bool object) {
    std::string step;
    if (!stack_.empty()) {
      Open& top = stack_.back();
      if (top.object) step = stack_.size() == 1 ? top.key : "." + top.key;
      else step = "[" + std::to_string(top.count++) + "]";
    }
    if (stack_.size() >= kMaxJsonDepth)
      throw JsonStructureError(path_to(step) + ": objects and arrays nested deeper than " + std::to_string(kMaxJsonDepth) +
                               " levels");
    stack_.push_back(Open{object, std::move(step), {}, {}, 0});
    return true;
  }
  // the JSON path of the innermost open level, then `last` (built only for an error)
  std::string path_to(const std::string& last) const {
    std::string p;
    for (const Open& o : stack_) p += o.step;
    return short_json_path(p + last);
  }

  nlohmann::detail::json_sax_dom_parser<json> dom_;
  std::vector<Open> stack_;
};

}  // namespace detail

/// json::parse(text) that throws DuplicateKeyError for a key given twice in one object and
/// JsonStructureError for objects and arrays nested deeper than kMaxJsonDepth or a NUL byte
/// anywhere in the text (json::exception for malformed text, as json::parse). Time and
/// memory are linear in the text (json_sax_dom_parser with a stack of the open levels, each
/// holding only its own step of the JSON path).
inline nlohmann::json parse_unique_keys(const std::string& text, bool ignore_comments = false) {
  using json = nlohmann::json;
  if (const std::size_t nul = text.find('\0'); nul != std::string::npos)
    throw JsonStructureError("malformed JSON: a NUL byte at byte offset " + std::to_string(nul) +
                             " (JSON text has none; the parser would stop there)");
  json result;
  detail::UniqueKeySax sax(result);
  json::sax_parse(text, &sax, json::input_format_t::json, /*strict=*/true, ignore_comments);
  return result;
}

}  // namespace magsim::scenes
