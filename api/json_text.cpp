// JSON text written through a buffer (api/json_text.hpp).
#include "api/json_text.hpp"

#include <array>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <cstring>

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
        const auto written =
            value.type() == Type::number_integer
                ? std::to_chars(digits, digits + sizeof digits, value.get<std::int64_t>())
                : std::to_chars(digits, digits + sizeof digits, value.get<std::uint64_t>());
        Put(digits, static_cast<std::size_t>(written.ptr - digits));
        return;
      }
      case Type::number_float: {
        const double x = value.get<double>();
        if (!std::isfinite(x)) {
          Put("null", 4);
          return;
        }
        char digits[64];
        const char* end = nlohmann::detail::to_chars(digits, digits + sizeof digits, x);
        Put(digits, static_cast<std::size_t>(end - digits));
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
    for (const char c : text) {
      if (!kPlain[static_cast<unsigned char>(c)]) {
        const std::string escaped = DumpWithNlohmann(nlohmann::json(text));
        Put(escaped.data(), escaped.size());
        return;
      }
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

}  // namespace sweetspot::api
