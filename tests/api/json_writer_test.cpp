// api::JsonWriter writes the bytes AppendJson writes for the tree the same calls build: each
// object's members sorted by key however they were written (nested objects, arrays of objects,
// a detached object), a key written twice keeping its last value, keys and strings that need
// escaping, and every kind of number. A renderer written once against the Out interface gives
// the same text through TreeObject and TextObject.
#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "api/json_text.hpp"
#include "api/json_writer.hpp"

namespace sweetspot::api {
namespace {

using Json = nlohmann::json;

// A renderer as the api's are written: members out of key order on purpose, a nested object,
// an array of objects, a detached object, a key set twice, keys and strings to escape.
template <class Out>
void Fill(Out& out) {
  out.Set("zeta", 1.5);
  out.Set("alpha", std::string("first"));
  out.Object("middle", [](Out& m) {
    m.Set("y", -2);
    m.Set("x", std::numeric_limits<std::uint64_t>::max());
    m.Set("quote\"key", "tab\there");
    m.Set("newline\nkey", nullptr);
    m.Set("\xc3\xa9t\xc3\xa9", "caf\xc3\xa9");  // UTF-8 key and value (sorted after ASCII)
  });
  out.Objects("rows", 3, [](std::size_t i, Out& row) {
    row.Set("value", static_cast<double>(i) / 3.0);
    row.Set("index", i);
  });
  {
    typename Out::Detached apart;
    apart.out().Set("second", false);
    apart.out().Set("first", true);
    out.Attach("detached", apart);
  }
  out.Set("alpha", std::string("last"));  // written again: the last value stays
  out.Set("list", std::vector<std::string>{"b", "a"});
  out.Set("tree", Json::parse(R"({"b": [1, 2.5, null], "a": {"d": 1, "c": "x"}})"));
  out.Set("not_finite", std::numeric_limits<double>::infinity());
  out.Set("minus_zero", -0.0);
  out.Set("tiny", 5e-324);
  out.Set("big", -1.7976931348623157e308);
  out.Object("empty", [](Out&) {});
  out.Objects("no_rows", 0, [](std::size_t, Out&) {});
}

std::string ViaTree() {
  Json tree = Json::object();
  TreeObject out(&tree);
  Fill(out);
  std::string text;
  AppendJson(tree, &text);
  return text;
}

std::string ViaText() {
  std::string text;
  JsonWriter writer(&text);
  {
    TextObject out(&writer);
    Fill(out);
  }
  return text;
}

TEST(JsonWriterTest, TextIsTheTreesDumpWhateverTheOrderOfTheCalls) {
  const std::string tree = ViaTree();
  EXPECT_EQ(ViaText(), tree);
  // The tree's own dump (nlohmann's serializer) is the reference of AppendJson's bytes.
  Json rebuilt = Json::object();
  TreeObject out(&rebuilt);
  Fill(out);
  EXPECT_EQ(tree, rebuilt.dump(-1, ' ', false, Json::error_handler_t::replace));
  // Spot checks of what the comparison covers: sorted keys, the last of a twice-written key,
  // null for a non-finite number, nlohmann's escaping.
  EXPECT_EQ(tree.rfind("{\"alpha\":\"last\",\"big\":", 0), 0u) << tree;
  EXPECT_NE(tree.find("\"not_finite\":null"), std::string::npos) << tree;
  EXPECT_NE(tree.find("\"quote\\\"key\":\"tab\\there\""), std::string::npos) << tree;
  EXPECT_NE(tree.find("\"rows\":[{\"index\":0,\"value\":0.0},"), std::string::npos) << tree;
}

TEST(JsonWriterTest, KeysSortByTheirBytesNotTheirEscapedText) {
  // '\n' (0x0a) sorts before 'a' although its escaped text "\\n" starts with '\\' (0x5c);
  // '"' (0x22) sorts before '#' (0x23) although it is written as "\\\"".
  std::string text;
  JsonWriter writer(&text);
  writer.BeginObject();
  writer.Key("a");
  writer.Integer(1);
  writer.Key("#");
  writer.Integer(2);
  writer.Key("\"");
  writer.Integer(3);
  writer.Key("\n");
  writer.Integer(4);
  writer.EndObject();
  const Json expected = {{"a", 1}, {"#", 2}, {"\"", 3}, {"\n", 4}};
  EXPECT_EQ(text, expected.dump());
  EXPECT_EQ(text, "{\"\\n\":4,\"\\\"\":3,\"#\":2,\"a\":1}");
}

TEST(JsonWriterTest, ArraysAndRawValuesTakeCommasBetweenElements) {
  std::string text = "prefix:";  // appended to, as the answer's text is
  JsonWriter writer(&text);
  writer.BeginArray();
  writer.Raw("{\"a\":1}");
  writer.BeginObject();
  writer.EndObject();
  writer.BeginArray();
  writer.EndArray();
  writer.String("s");
  writer.Bool(true);
  writer.Null();
  writer.Number(std::numeric_limits<double>::quiet_NaN());
  writer.Unsigned(7);
  writer.Integer(std::numeric_limits<std::int64_t>::min());
  writer.Value(Json::parse(R"({"z": 1, "y": [true]})"));
  writer.EndArray();
  EXPECT_EQ(text,
            "prefix:[{\"a\":1},{},[],\"s\",true,null,null,7,-9223372036854775808,"
            "{\"y\":[true],\"z\":1}]");
}

}  // namespace
}  // namespace sweetspot::api
