// ReadPlainBody (api/json_reader.hpp): a request body read into nlohmann's tree without
// nlohmann's lexer, for the bodies pipelines send: strings of printable ASCII without escapes,
// numbers JSON's grammar allows and a double holds, within the request limits. nlohmann's
// lexer reads a character at a time through its token buffers (1.4 µs of the 2.2 µs the
// contract's 260-byte example took to parse, bench/api_request.cpp); this reads the same body
// into the same tree in about a third of that. Anything else (an escape, a control character,
// UTF-8, an invalid or out-of-range number, a limit reached, invalid JSON) is left to nlohmann
// (ParseBody's LimitedSax), so its refusals and their messages are unchanged.
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <string>

#include "api/json_reader.hpp"

namespace sweetspot::api {
namespace {

using Json = nlohmann::json;

// Recursive descent over [at, end): each function reads one value into *out, false where the
// body leaves the plain subset (the caller then discards what was read). Its depth is
// limits.max_json_depth at most (at most 512, ApiLimits::Validate): a few hundred frames.
class PlainReader {
 public:
  PlainReader(std::string_view body, const ApiLimits& limits)
      : at_(body.data()), end_(body.data() + body.size()), limits_(limits) {}

  // The whole body: one value and nothing but whitespace after it.
  bool Body(Json* out) {
    if (!Value(out, 0)) return false;
    SkipSpace();
    return at_ == end_;
  }

 private:
  void SkipSpace() {
    while (at_ < end_ && (*at_ == ' ' || *at_ == '\n' || *at_ == '\r' || *at_ == '\t')) ++at_;
  }

  bool Value(Json* out, int depth) {
    SkipSpace();
    if (at_ == end_) return false;
    switch (*at_) {
      case '{':
        return Object(out, depth);
      case '[':
        return Array(out, depth);
      case '"': {
        std::string text;
        if (!String(&text)) return false;
        *out = std::move(text);
        return true;
      }
      case 't':
        return Word("true", 4) && (*out = true, true);
      case 'f':
        return Word("false", 5) && (*out = false, true);
      case 'n':
        return Word("null", 4) && (*out = nullptr, true);
      default:
        return Number(out);
    }
  }

  bool Word(const char* word, std::size_t n) {
    if (static_cast<std::size_t>(end_ - at_) < n || std::memcmp(at_, word, n) != 0) return false;
    at_ += n;
    return true;
  }

  // A string of printable ASCII without escapes, at most max_string_length bytes.
  bool String(std::string* out) {
    const char* begin = ++at_;  // after the quote
    while (at_ < end_) {
      const auto c = static_cast<unsigned char>(*at_);
      if (c == '"') break;
      if (c < 0x20 || c >= 0x80 || c == '\\') return false;
      ++at_;
    }
    if (at_ == end_) return false;
    const auto size = static_cast<std::size_t>(at_ - begin);
    if (size > limits_.max_string_length) return false;
    out->assign(begin, size);
    ++at_;  // the closing quote
    return true;
  }

  // What follows an object's or array's opening bracket: items read by item() (false: not
  // plain), separated by commas, up to `close`.
  template <class Item>
  bool Items(char close, Item item) {
    SkipSpace();
    if (at_ < end_ && *at_ == close) {
      ++at_;
      return true;
    }
    while (true) {
      if (!item()) return false;
      SkipSpace();
      if (at_ == end_) return false;
      if (*at_ == ',') {
        ++at_;
        continue;
      }
      if (*at_ != close) return false;
      ++at_;
      return true;
    }
  }

  bool Object(Json* out, int depth) {
    if (depth >= limits_.max_json_depth) return false;
    ++at_;  // '{'
    *out = Json::object();
    auto& members = out->get_ref<Json::object_t&>();
    return Items('}', [&] {
      SkipSpace();
      if (at_ == end_ || *at_ != '"') return false;
      std::string key;
      if (!String(&key)) return false;
      SkipSpace();
      if (at_ == end_ || *at_ != ':') return false;
      ++at_;
      Json value;
      if (!Value(&value, depth + 1)) return false;
      // A key given twice keeps its last value, as nlohmann's tree does.
      members.insert_or_assign(std::move(key), std::move(value));
      return true;
    });
  }

  bool Array(Json* out, int depth) {
    if (depth >= limits_.max_json_depth) return false;
    ++at_;  // '['
    *out = Json::array();
    auto& items = out->get_ref<Json::array_t&>();
    return Items(']', [&] {
      if (items.size() >= limits_.max_array_length) return false;
      items.emplace_back();
      return Value(&items.back(), depth + 1);
    });
  }

  // -?(0|[1-9][0-9]*)(.[0-9]+)?([eE][+-]?[0-9]+)?, read as nlohmann's lexer reads it: an integer
  // as a signed (with a minus) or unsigned 64-bit integer, anything else by strtod. An integer
  // out of 64 bits, or a double out of range, is left to nlohmann.
  bool Number(Json* out) {
    const char* begin = at_;
    auto digits = [this] {
      const char* first = at_;
      while (at_ < end_ && *at_ >= '0' && *at_ <= '9') ++at_;
      return at_ - first;
    };
    const bool negative = at_ < end_ && *at_ == '-';
    if (negative) ++at_;
    if (at_ == end_) return false;
    if (*at_ == '0') {
      ++at_;
    } else if (*at_ >= '1' && *at_ <= '9') {
      digits();
    } else {
      return false;
    }
    bool integer = true;
    if (at_ < end_ && *at_ == '.') {
      ++at_;
      if (digits() == 0) return false;
      integer = false;
    }
    if (at_ < end_ && (*at_ == 'e' || *at_ == 'E')) {
      ++at_;
      if (at_ < end_ && (*at_ == '+' || *at_ == '-')) ++at_;
      if (digits() == 0) return false;
      integer = false;
    }
    if (integer) {
      if (negative) {
        std::int64_t value = 0;
        const auto read = std::from_chars(begin, at_, value);
        if (read.ec != std::errc() || read.ptr != at_) return false;
        *out = value;
      } else {
        std::uint64_t value = 0;
        const auto read = std::from_chars(begin, at_, value);
        if (read.ec != std::errc() || read.ptr != at_) return false;
        *out = value;
      }
      return true;
    }
    // strtod, as nlohmann's lexer, on a terminated copy.
    char text[64];
    const auto size = static_cast<std::size_t>(at_ - begin);
    if (size >= sizeof text) return false;
    std::memcpy(text, begin, size);
    text[size] = '\0';
    char* stop = nullptr;
    errno = 0;
    const double value = std::strtod(text, &stop);
    if (stop != text + size || errno != 0 || !std::isfinite(value)) return false;
    *out = value;
    return true;
  }

  const char* at_;
  const char* end_;
  const ApiLimits& limits_;
};

}  // namespace

bool ReadPlainBody(std::string_view body, const ApiLimits& limits, nlohmann::json* out) {
  Json value;
  if (!PlainReader(body, limits).Body(&value)) return false;
  *out = std::move(value);
  return true;
}

}  // namespace sweetspot::api
