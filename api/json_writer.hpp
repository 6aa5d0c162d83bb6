// An answer written straight to JSON text, without a nlohmann tree in between, and one way of
// rendering that serves both: a renderer written once against the Out interface below
// (`template <class Out> void Write...(..., Out& out)`) builds a nlohmann tree with TreeObject
// (what explore, the CLI and the tests read) or writes text with TextObject (the server's
// answers). The text is byte for byte what AppendJson writes for the tree the same calls build:
// JsonWriter sorts each object's members by key when the object closes, as nlohmann's std::map
// orders them, and writes numbers and strings as nlohmann's compact dump does.
//
// The Out interface (TreeObject and TextObject):
//   Set(key, value)      a member: double, integer, bool, string, nullptr, a vector of strings,
//                        or a nlohmann::json subtree; a key set twice keeps the last value
//   Object(key, fill)    a member that is an object, filled by fill(Out&)
//   Objects(key, n, fill)  a member that is an array of n objects, fill(i, Out&)
//   Detached / Attach    an object filled apart (e.g. "error_estimate", written while the
//                        outputs' blocks are) and set as a member once complete
// TreeOf(fill) gives a renderer's tree as a value (SummaryToJson and its kin).
#pragma once

#include <boost/container/small_vector.hpp>
#include <nlohmann/json.hpp>

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

namespace sweetspot::api {

/// Writes compact JSON text to a string: objects with their members sorted by key (bytewise, as
/// std::string compares; a key written twice keeps its last value), numbers and strings as
/// nlohmann's dump(-1, ' ', false, replace) writes them, a non-finite number as null.
/// Calls must nest properly (BeginObject, Key, a value, ..., EndObject); not thread-safe.
class JsonWriter {
 public:
  /// Appends to *out, which must outlive the writer.
  explicit JsonWriter(std::string* out);

  void BeginObject();  ///< '{'
  void EndObject();    ///< '}', the object's members sorted by key
  void BeginArray();   ///< '['
  void EndArray();     ///< ']'
  /// The next member's key (inside an object only).
  void Key(std::string_view key);
  void Number(double value);           ///< A number (null when not finite).
  void Integer(std::int64_t value);    ///< A signed integer.
  void Unsigned(std::uint64_t value);  ///< An unsigned integer.
  void Bool(bool value);               ///< true or false.
  void Null();                         ///< null.
  void String(std::string_view text);  ///< A string, escaped as nlohmann escapes it.
  /// A nlohmann value, written as AppendJson writes it.
  void Value(const nlohmann::json& value);
  /// A value already written as compact JSON text (by another JsonWriter).
  void Raw(std::string_view json_text);

  /// Any value type Out::Set takes.
  template <class T>
  void Put(const T& value) {
    if constexpr (std::is_same_v<T, bool>) {
      Bool(value);
    } else if constexpr (std::is_integral_v<T> && std::is_signed_v<T>) {
      Integer(static_cast<std::int64_t>(value));
    } else if constexpr (std::is_integral_v<T>) {
      Unsigned(static_cast<std::uint64_t>(value));
    } else if constexpr (std::is_floating_point_v<T>) {
      Number(static_cast<double>(value));
    } else if constexpr (std::is_same_v<T, std::nullptr_t>) {
      Null();
    } else if constexpr (std::is_same_v<T, nlohmann::json>) {
      Value(value);
    } else if constexpr (std::is_same_v<T, std::vector<std::string>>) {
      BeginArray();
      for (const std::string& item : value) String(item);
      EndArray();
    } else {
      static_assert(std::is_convertible_v<const T&, std::string_view>, "not a JSON value type");
      String(std::string_view(value));
    }
  }

 private:
  // An object or array being written.
  struct Frame {
    bool object = false;           // else an array
    bool empty = true;             // no member or element yet
    std::size_t open = 0;          // the offset of its '{' or '['
    std::size_t first_member = 0;  // its members' first index in members_
  };
  // A member of an open object: where its text begins (its key's quote) and its key.
  struct Member {
    std::size_t begin = 0;     // offset in *out_ of the member's '"'
    std::size_t key = 0;       // offset of the key's bytes in *out_, or in raw_keys_ if raw
    std::size_t key_size = 0;  // the key's length, bytes
    bool raw = false;          // the key needed escaping: its bytes are kept in raw_keys_
  };

  void BeforeValue();  // a comma before an array's second and later elements
  std::string_view KeyOf(const Member& member) const;
  void SortMembers(const Frame& frame);  // reorders the object's members by key
  void Escaped(std::string_view text);   // a string through nlohmann's escaping

  std::string* out_;
  // In the writer itself for an answer's usual nesting and members (no allocation).
  boost::container::small_vector<Frame, 8> frames_;
  boost::container::small_vector<Member, 32> members_;
  std::string raw_keys_;  // the keys that needed escaping, as given
  std::string scratch_;   // an object's members while they are reordered
  boost::container::small_vector<std::size_t, 32> order_;  // their indices in key order
};

/// The Out interface over a nlohmann object (the tree the renderers have always built).
class TreeObject {
 public:
  /// Members go into *object (made an object when it is null); it must outlive this.
  explicit TreeObject(nlohmann::json* object) : object_(object) {
    if (object_->is_null()) *object_ = nlohmann::json::object();
  }
  /// The object written to.
  nlohmann::json* json() const { return object_; }
  /// Sets member `key` to `value`.
  template <class T>
  void Set(std::string_view key, T&& value) {
    (*object_)[std::string(key)] = std::forward<T>(value);
  }
  /// Sets member `key` to an object that fill(TreeObject&) fills.
  template <class F>
  void Object(std::string_view key, F&& fill) {
    nlohmann::json child = nlohmann::json::object();
    TreeObject out(&child);
    fill(out);
    (*object_)[std::string(key)] = std::move(child);
  }
  /// Sets member `key` to an array of `n` objects, object i filled by fill(i, TreeObject&).
  template <class F>
  void Objects(std::string_view key, std::size_t n, F&& fill) {
    nlohmann::json items = nlohmann::json::array();
    for (std::size_t i = 0; i < n; ++i) {
      nlohmann::json child = nlohmann::json::object();
      TreeObject out(&child);
      fill(i, out);
      items.push_back(std::move(child));
    }
    (*object_)[std::string(key)] = std::move(items);
  }
  /// An object filled apart, then set with Attach.
  using Detached = class TreeDetached;
  /// Sets member `key` to `detached`'s object (moved out).
  void Attach(std::string_view key, TreeDetached& detached);

 private:
  nlohmann::json* object_;
};

/// The tree a generic renderer writes: a new object that fill(TreeObject&) fills.
template <class F>
nlohmann::json TreeOf(F&& fill) {
  nlohmann::json out = nlohmann::json::object();
  TreeObject tree(&out);
  fill(tree);
  return out;
}

/// The Out interface over a JsonWriter: an object opened on construction and closed (its
/// members sorted) on destruction.
class TextObject {
 public:
  /// Opens an object on `writer`, which must outlive this.
  explicit TextObject(JsonWriter* writer) : writer_(writer) { writer_->BeginObject(); }
  ~TextObject() { writer_->EndObject(); }
  TextObject(const TextObject&) = delete;
  TextObject& operator=(const TextObject&) = delete;

  /// Writes member `key` with `value`.
  template <class T>
  void Set(std::string_view key, const T& value) {
    writer_->Key(key);
    writer_->Put(value);
  }
  /// Writes member `key` as an object that fill(TextObject&) fills.
  template <class F>
  void Object(std::string_view key, F&& fill) {
    writer_->Key(key);
    TextObject out(writer_);
    fill(out);
  }
  /// Writes member `key` as an array of `n` objects, object i filled by fill(i, TextObject&).
  template <class F>
  void Objects(std::string_view key, std::size_t n, F&& fill) {
    writer_->Key(key);
    writer_->BeginArray();
    for (std::size_t i = 0; i < n; ++i) {
      TextObject out(writer_);
      fill(i, out);
    }
    writer_->EndArray();
  }
  /// An object written apart (to a writer of its own), then written as a member with Attach.
  using Detached = class TextDetached;
  /// Writes member `key` as `detached`'s object.
  void Attach(std::string_view key, TextDetached& detached);

 private:
  JsonWriter* writer_;
};

/// TreeObject's Detached: an object filled apart, then set with TreeObject::Attach.
class TreeDetached {
 public:
  TreeDetached() : out_(&value_) {}
  TreeDetached(const TreeDetached&) = delete;
  TreeDetached& operator=(const TreeDetached&) = delete;
  TreeObject& out() { return out_; }          ///< Where its members go.
  nlohmann::json& value() { return value_; }  ///< The object.

 private:
  nlohmann::json value_ = nlohmann::json::object();
  TreeObject out_;
};

inline void TreeObject::Attach(std::string_view key, TreeDetached& detached) {
  Set(key, std::move(detached.value()));
}

/// TextObject's Detached: an object written to a writer of its own, then written as a member
/// with TextObject::Attach.
class TextDetached {
 public:
  TextDetached() : writer_(&text_), out_(std::in_place, &writer_) {}
  TextDetached(const TextDetached&) = delete;
  TextDetached& operator=(const TextDetached&) = delete;
  TextObject& out() { return *out_; }  ///< Where its members go.
  /// Its text, the object closed.
  std::string_view Close() {
    out_.reset();
    return text_;
  }

 private:
  std::string text_;
  JsonWriter writer_;
  std::optional<TextObject> out_;
};

inline void TextObject::Attach(std::string_view key, TextDetached& detached) {
  writer_->Key(key);
  writer_->Raw(detached.Close());
}

}  // namespace sweetspot::api
