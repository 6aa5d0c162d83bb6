#include "api/explore/columns.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>

#include "api/bat_json.hpp"
#include "api/explore/shards.hpp"
#include "api/json_reader.hpp"
#include "api/outputs/scene_outputs.hpp"
#include "api/scene_json.hpp"

namespace sweetspot::api {
namespace {

using Json = nlohmann::json;

bool IsDecimalIndex(const std::string& token) {
  return !token.empty() && token.size() <= 9 &&
         std::all_of(token.begin(), token.end(), [](char c) { return c >= '0' && c <= '9'; });
}

// "a, b, c" of an object's keys.
std::string KeysOf(const Json& object) {
  std::string keys;
  for (const auto& item : object.items()) keys += (keys.empty() ? "" : ", ") + item.key();
  return keys;
}

const char* KindOf(const Json& value) {
  if (value.is_number()) return "a number";
  if (value.is_string()) return "a string";
  if (value.is_boolean()) return "a boolean";
  return "a value";
}

}  // namespace

ExploreColumn MakeColumn(const std::string& path) { return {path, ObjectiveTokens(path)}; }

Json RowShape(const std::vector<std::string>& parameter_paths, const RowOutputs& outputs) {
  Json shape{
      {"index", 0}, {"feasible", true}, {"error", {{"code", ""}, {"message", ""}, {"field", ""}}}};
  Json parameters = Json::object();
  for (const std::string& path : parameter_paths) parameters[path] = 0.0;
  shape["parameters"] = std::move(parameters);
  if (!outputs.scene.empty()) {
    Json rendered = SceneResultToJson(ProbeResult(outputs.scene));
    for (const core::SceneOutput output : outputs.scene) {
      const char* name = core::SceneOutputName(output);
      if (rendered.contains(name)) shape[name] = std::move(rendered[name]);
    }
  }
  if (outputs.properties) shape["properties"] = PropertiesToJson(core::MassProperties{}, 0.0);
  if (outputs.collision_efficiency) shape["collision_efficiency"] = 0.0;
  if (outputs.swing) {
    core::Swing swing;
    swing.bat_speed_mps = 0.0;
    shape["swing"] = SwingToJson(swing);
  }
  return shape;
}

bool CheckColumn(const ExploreColumn& column, const Json& shape, std::string* why) {
  const Json* node = &shape;
  std::string where = "a row";
  for (const std::string& token : column.tokens) {
    if (node->is_object()) {
      const auto it = node->find(token);
      if (it == node->end()) {
        *why = where + " has no field " + Show(Json(token)) + " (known: " + KeysOf(*node) + ")";
        if (node == &shape) *why += "; outputs and parameters name what a row has";
        return false;
      }
      node = &*it;
    } else if (node->is_array()) {
      if (!IsDecimalIndex(token)) {
        *why = where + " is an array: the next part must be an index (0, 1, ...), not " +
               Show(Json(token));
        return false;
      }
      if (node->empty()) return true;  // nothing known of its elements
      node = &node->front();
    } else {
      *why = where + " is " + KindOf(*node) + ": it has no field " + Show(Json(token));
      return false;
    }
    where = where == "a row" ? token : where + "." + token;
  }
  return true;
}

std::vector<ExploreColumn> DefaultCsvColumns(const std::vector<std::string>& parameter_paths,
                                             const Json& shape) {
  std::vector<ExploreColumn> columns{MakeColumn("index")};
  for (const std::string& path : parameter_paths)
    columns.push_back(MakeColumn("parameters." + path));
  columns.push_back(MakeColumn("feasible"));
  for (const auto& item : shape.items()) {
    const std::string& name = item.key();
    if (name == "index" || name == "feasible" || name == "error" || name == "parameters") continue;
    if (item.value().is_object()) {
      for (const auto& field : item.value().items()) {
        if (field.value().is_primitive() && !field.value().is_null()) {
          columns.push_back(MakeColumn(name + "." + field.key()));
        }
      }
    } else if (item.value().is_primitive() && !item.value().is_null()) {
      columns.push_back(MakeColumn(name));
    }
  }
  columns.push_back(MakeColumn("error.code"));
  return columns;
}

Json ProjectRow(const Json& row, const std::vector<ExploreColumn>& columns) {
  Json out = Json::object();
  for (const ExploreColumn& column : columns) {
    const Json* value = FindAt(row, column.tokens);
    out[column.path] = value != nullptr ? *value : Json(nullptr);
  }
  return out;
}

void AppendCsvField(std::string_view text, std::string* out) {
  if (text.find_first_of(",\"\r\n") == std::string_view::npos) {
    out->append(text);
    return;
  }
  out->push_back('"');
  for (const char c : text) {
    if (c == '"') out->push_back('"');
    out->push_back(c);
  }
  out->push_back('"');
}

void AppendCsvNumber(double value, std::string* out) {
  if (!std::isfinite(value)) return;
  char buffer[32];  // the shortest form of a double takes at most 24 characters
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  out->append(buffer, result.ptr);
}

void CsvRowWriter::Separate() {
  if (!first_) out_->push_back(',');
  first_ = false;
}

void CsvRowWriter::Number(double value) {
  Separate();
  AppendCsvNumber(value, out_);
}

std::string_view CsvNumberText(double value, CsvNumberMemo* memo) {
  std::uint64_t bits = 0;
  std::memcpy(&bits, &value, sizeof bits);
  if (!(memo->set && memo->bits == bits)) {
    // AppendCsvNumber's text: nothing for NaN or an infinity.
    const char* end = memo->text;
    if (std::isfinite(value))
      end = std::to_chars(memo->text, memo->text + sizeof(memo->text), value).ptr;
    memo->size = static_cast<unsigned char>(end - memo->text);
    memo->bits = bits;
    memo->set = true;
  }
  return {memo->text, memo->size};
}

void CsvRowWriter::Number(double value, CsvNumberMemo* memo) {
  Separate();
  out_->append(CsvNumberText(value, memo));
}

void CsvRowWriter::Integer(std::int64_t value) {
  Separate();
  char buffer[24];
  out_->append(buffer, std::to_chars(buffer, buffer + sizeof(buffer), value).ptr);
}

void CsvRowWriter::Unsigned(std::uint64_t value) {
  Separate();
  char buffer[24];
  out_->append(buffer, std::to_chars(buffer, buffer + sizeof(buffer), value).ptr);
}

void CsvRowWriter::Bool(bool value) {
  Separate();
  out_->append(value ? "true" : "false");
}

void CsvRowWriter::String(std::string_view value) {
  Separate();
  AppendCsvField(value, out_);
}

void CsvRowWriter::Empty() { Separate(); }

void CsvRowWriter::EndRow() {
  out_->push_back('\n');
  first_ = true;
}

void AppendCsvHeader(const std::vector<ExploreColumn>& columns, std::string* out) {
  CsvRowWriter writer(out);
  for (const ExploreColumn& column : columns) writer.String(column.path);
  writer.EndRow();
}

void AppendCsvRow(const Json& row, const std::vector<ExploreColumn>& columns, std::string* out) {
  CsvRowWriter writer(out);
  for (const ExploreColumn& column : columns) {
    const Json* value = FindAt(row, column.tokens);
    if (value == nullptr || value->is_null()) {
      writer.Empty();
    } else if (value->is_number_unsigned()) {
      writer.Unsigned(value->get<std::uint64_t>());
    } else if (value->is_number_integer()) {
      writer.Integer(value->get<std::int64_t>());
    } else if (value->is_number_float()) {
      writer.Number(value->get<double>());
    } else if (value->is_boolean()) {
      writer.Bool(value->get<bool>());
    } else if (value->is_string()) {
      writer.String(value->get_ref<const std::string&>());
    } else {
      writer.String(value->dump(-1, ' ', false, Json::error_handler_t::replace));
    }
  }
  writer.EndRow();
}

}  // namespace sweetspot::api
