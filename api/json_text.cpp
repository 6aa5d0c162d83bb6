// JSON text written through a buffer (api/json_text.hpp), and JsonWriter
// (api/json_writer.hpp): both write numbers and strings through the same helpers.
#include "api/json_text.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <string_view>

#include "api/json_writer.hpp"

namespace sweetspot::api {
namespace {

// One value as nlohmann's compact dump writes it (invalid UTF-8 replaced): for what the writer
// does not write itself.
std::string DumpWithNlohmann(const nlohmann::json& value) {
  return value.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

// The bytes nlohmann's escaping leaves as they are: printable ASCII but '"' and '\\'.
constexpr std::array<bool, 256> kPlain = [] {
  std::array<bool, 256> plain{};
  for (int c = 0x20; c < 0x80; ++c) plain[c] = c != '"' && c != '\\';
  return plain;
}();

// True when every byte of `text` is written as it is (kPlain).
bool IsPlain(std::string_view text) {
  return std::all_of(text.begin(), text.end(),
                     [](char c) { return kPlain[static_cast<unsigned char>(c)]; });
}

// A double's text as nlohmann's dump writes it (null when not finite), in `digits` or static.
std::string_view NumberText(double x, char (&digits)[64]) {
  if (!std::isfinite(x)) return "null";
  const char* end = nlohmann::detail::to_chars(digits, digits + sizeof digits, x);
  return {digits, static_cast<std::size_t>(end - digits)};
}

// An integer's text, in `digits`.
template <class Int>
std::string_view IntegerText(Int x, char (&digits)[24]) {
  const auto written = std::to_chars(digits, digits + sizeof digits, x);
  return {digits, static_cast<std::size_t>(written.ptr - digits)};
}

// Writes a value's text into a 1 KiB buffer handed to `sink(const char*, std::size_t)` when
// full and at the end: a call per kilobyte instead of a library call per character.
template <class Sink>
class Writer {
 public:
  explicit Writer(Sink& sink) : sink_(sink) {}
  ~Writer() { Flush(); }
  Writer(const Writer&) = delete;
  Writer& operator=(const Writer&) = delete;

  void Value(const nlohmann::json& value) {
    using Type = nlohmann::json::value_t;
    switch (value.type()) {
      case Type::null:
        Put("null", 4);
        return;
      case Type::boolean:
        value.get<bool>() ? Put("true", 4) : Put("false", 5);
        return;
      case Type::number_integer:
      case Type::number_unsigned: {
        char digits[24];
        const std::string_view text = value.type() == Type::number_integer
                                          ? IntegerText(value.get<std::int64_t>(), digits)
                                          : IntegerText(value.get<std::uint64_t>(), digits);
        Put(text.data(), text.size());
        return;
      }
      case Type::number_float: {
        char digits[64];
        const std::string_view text = NumberText(value.get<double>(), digits);
        Put(text.data(), text.size());
        return;
      }
      case Type::string:
        String(value.get_ref<const std::string&>());
        return;
      case Type::object: {
        Put('{');
        bool first = true;
        for (const auto& [key, item] : value.get_ref<const nlohmann::json::object_t&>()) {
          if (!first) Put(',');
          first = false;
          String(key);
          Put(':');
          Value(item);
        }
        Put('}');
        return;
      }
      case Type::array: {
        Put('[');
        bool first = true;
        for (const auto& item : value.get_ref<const nlohmann::json::array_t&>()) {
          if (!first) Put(',');
          first = false;
          Value(item);
        }
        Put(']');
        return;
      }
      case Type::binary:
      case Type::discarded: {
        const std::string text = DumpWithNlohmann(value);
        Put(text.data(), text.size());
        return;
      }
    }
  }

 private:
  static constexpr std::size_t kBytes = 1024;

  // A string as nlohmann writes it: written as it is when every byte is plain (kPlain),
  // otherwise (control characters, UTF-8, invalid bytes) through nlohmann's escaping.
  void String(const std::string& text) {
    if (!IsPlain(text)) {
      const std::string escaped = DumpWithNlohmann(nlohmann::json(text));
      Put(escaped.data(), escaped.size());
      return;
    }
    Put('"');
    Put(text.data(), text.size());
    Put('"');
  }
  void Put(char c) {
    if (used_ == kBytes) Flush();
    buffer_[used_++] = c;
  }
  void Put(const char* text, std::size_t n) {
    if (n > kBytes - used_) {
      Flush();
      if (n > kBytes) {
        sink_(text, n);
        return;
      }
    }
    std::memcpy(buffer_ + used_, text, n);
    used_ += n;
  }
  void Flush() {
    if (used_ > 0) sink_(static_cast<const char*>(buffer_), used_);
    used_ = 0;
  }

  Sink& sink_;
  char buffer_[kBytes];
  std::size_t used_ = 0;
};

}  // namespace

void AppendJson(const nlohmann::json& value, std::string* out) {
  auto sink = [out](const char* text, std::size_t n) { out->append(text, n); };
  Writer<decltype(sink)> writer(sink);
  writer.Value(value);
}

std::uint64_t JsonFnv1a64(const nlohmann::json& value) {
  std::uint64_t hash = 1469598103934665603ULL;
  auto sink = [&hash](const char* text, std::size_t n) {
    for (std::size_t i = 0; i < n; ++i) {
      hash ^= static_cast<unsigned char>(text[i]);
      hash *= 1099511628211ULL;
    }
  };
  {
    Writer<decltype(sink)> writer(sink);
    writer.Value(value);
  }  // the writer's last bytes reach the hash here
  return hash;
}

// ---- JsonWriter ----

JsonWriter::JsonWriter(std::string* out) : out_(out) {}

void JsonWriter::BeforeValue() {
  if (frames_.empty()) return;
  Frame& frame = frames_.back();
  if (frame.object) return;  // Key wrote the comma
  if (!frame.empty) out_->push_back(',');
  frame.empty = false;
}

void JsonWriter::BeginObject() {
  BeforeValue();
  frames_.push_back({true, true, out_->size(), members_.size()});
  out_->push_back('{');
}

void JsonWriter::EndObject() {
  const Frame frame = frames_.back();
  frames_.pop_back();
  SortMembers(frame);
  members_.resize(frame.first_member);
  if (members_.size() == 0) raw_keys_.clear();
  out_->push_back('}');
}

void JsonWriter::BeginArray() {
  BeforeValue();
  frames_.push_back({false, true, out_->size(), members_.size()});
  out_->push_back('[');
}

void JsonWriter::EndArray() {
  frames_.pop_back();
  out_->push_back(']');
}

void JsonWriter::Key(std::string_view key) {
  Frame& frame = frames_.back();
  Member member;
  member.key_size = key.size();
  if (IsPlain(key)) {  // [,]"key": in one step
    const std::size_t at = out_->size();
    const std::size_t comma = frame.empty ? 0 : 1;
    out_->resize(at + comma + key.size() + 3);
    char* p = out_->data() + at;
    if (comma != 0) *p++ = ',';
    member.begin = at + comma;
    *p++ = '"';
    member.key = member.begin + 1;
    std::memcpy(p, key.data(), key.size());
    p += key.size();
    *p++ = '"';
    *p = ':';
  } else {
    if (!frame.empty) out_->push_back(',');
    member.begin = out_->size();
    member.raw = true;
    member.key = raw_keys_.size();
    raw_keys_.append(key);
    Escaped(key);
    out_->push_back(':');
  }
  frame.empty = false;
  members_.push_back(member);
}

std::string_view JsonWriter::KeyOf(const Member& member) const {
  const std::string& from = member.raw ? raw_keys_ : *out_;
  return std::string_view(from).substr(member.key, member.key_size);
}

void JsonWriter::SortMembers(const Frame& frame) {
  const std::size_t first = frame.first_member;
  const std::size_t n = members_.size() - first;
  bool sorted = true;
  for (std::size_t i = first + 1; i < members_.size() && sorted; ++i) {
    sorted = KeyOf(members_[i - 1]) < KeyOf(members_[i]);
  }
  if (sorted) return;  // the usual case: renderers write their members in key order
  // An insertion sort (an object has tens of members at most), stable: of equal keys the one
  // written last ends last.
  order_.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t i = first + k;
    std::size_t j = k;
    for (; j > 0 && KeyOf(members_[i]) < KeyOf(members_[order_[j - 1]]); --j) {
      order_[j] = order_[j - 1];
    }
    order_[j] = i;
  }
  // A key written again replaces the earlier value: of equal keys the last is kept (marked by
  // a member index past the end).
  for (std::size_t k = 0; k + 1 < n; ++k) {
    if (KeyOf(members_[order_[k]]) == KeyOf(members_[order_[k + 1]])) order_[k] = members_.size();
  }
  // Each member's text runs from its quote to the comma before the next (the last: to the end).
  const std::size_t body = frame.open + 1;
  scratch_.assign(*out_, body, std::string::npos);
  out_->resize(body);
  bool any = false;
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t i = order_[k];
    if (i == members_.size()) continue;
    const std::size_t begin = members_[i].begin - body;
    const std::size_t end =
        i + 1 < members_.size() ? members_[i + 1].begin - 1 - body : scratch_.size();
    if (any) out_->push_back(',');
    any = true;
    out_->append(scratch_, begin, end - begin);
  }
}

void JsonWriter::Number(double value) {
  BeforeValue();
  char digits[64];
  out_->append(NumberText(value, digits));
}

void JsonWriter::Integer(std::int64_t value) {
  BeforeValue();
  char digits[24];
  out_->append(IntegerText(value, digits));
}

void JsonWriter::Unsigned(std::uint64_t value) {
  BeforeValue();
  char digits[24];
  out_->append(IntegerText(value, digits));
}

void JsonWriter::Bool(bool value) {
  BeforeValue();
  value ? out_->append("true", 4) : out_->append("false", 5);
}

void JsonWriter::Null() {
  BeforeValue();
  out_->append("null", 4);
}

void JsonWriter::String(std::string_view text) {
  BeforeValue();
  if (!IsPlain(text)) {
    Escaped(text);
    return;
  }
  const std::size_t at = out_->size();
  out_->resize(at + text.size() + 2);
  char* p = out_->data() + at;
  *p++ = '"';
  std::memcpy(p, text.data(), text.size());
  p[text.size()] = '"';
}

void JsonWriter::Escaped(std::string_view text) {
  out_->append(DumpWithNlohmann(nlohmann::json(std::string(text))));
}

void JsonWriter::Value(const nlohmann::json& value) {
  BeforeValue();
  AppendJson(value, out_);
}

void JsonWriter::Raw(std::string_view json_text) {
  BeforeValue();
  out_->append(json_text);
}

}  // namespace sweetspot::api
