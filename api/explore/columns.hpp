// The columns of a /v1/explore answer ("columns": [dotted paths]) and its CSV
// output ("format": "csv"). A column is a dotted path into a design's row as
// the Pareto objectives name them ("parameters.<swept path>" keeps the swept
// path whole, "max_exit_speed.exit_speed_mps", "error.code", "index");
// CheckColumn refuses, before the first design, a path no row of the sweep can
// have. CsvRowWriter writes a row from its values (not from a JSON tree), so a
// sweep engine that never builds one can feed it; AppendCsvRow feeds it from
// a JSON row.
#pragma once

#include <nlohmann/json.hpp>

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "api/explore/design.hpp"

namespace sweetspot::api {

/// One column: a dotted path into a row.
struct ExploreColumn {
  std::string path;                 ///< As written, e.g. "parameters.fill.depth_m".
  std::vector<std::string> tokens;  ///< ObjectiveTokens(path).
};

/// Makes a column from its path as written.
ExploreColumn MakeColumn(const std::string& path);

/// What every row of one sweep can hold: index, feasible, error.{code, message, field},
/// parameters.<each swept path> and the requested outputs with every field they render.
/// A JSON object of that shape (arrays hold one element, values are placeholders).
nlohmann::json RowShape(const std::vector<std::string>& parameter_paths, const RowOutputs& outputs);

/// True when `column` names a part of `shape` (an array part takes a decimal index, checked
/// against no length: an index past a row's array is an empty cell). Otherwise false with the
/// rule broken in *why, e.g. "max_exit_speed has no field exit_speed_mp (known: ...)".
bool CheckColumn(const ExploreColumn& column, const nlohmann::json& shape, std::string* why);

/// The columns of a CSV answer without "columns": index, parameters.<each swept path>,
/// feasible, the number, string and boolean fields of each requested output (outputs and
/// their fields in the row's alphabetical order; nested objects and arrays are left out),
/// error.code.
std::vector<ExploreColumn> DefaultCsvColumns(const std::vector<std::string>& parameter_paths,
                                             const nlohmann::json& shape);

/// A json/ndjson row with "columns": an object keyed by each column's path as written (flat,
/// the keys of the CSV header), its value the row's value there, or null when the row has
/// none (an infeasible design's outputs, a feasible one's error.code).
nlohmann::json ProjectRow(const nlohmann::json& row, const std::vector<ExploreColumn>& columns);

/// Appends `text` as one RFC 4180 field: quoted (quotes doubled) when it holds a comma,
/// a double quote, CR or LF; as is otherwise.
void AppendCsvField(std::string_view text, std::string* out);

/// Appends the shortest decimal text that strtod reads back as `value`, bit for bit
/// (std::to_chars); nothing for NaN or an infinity (rows never hold them).
void AppendCsvNumber(double value, std::string* out);

/// The text of the last number one column wrote (AppendCsvNumber's), reused while the column's
/// value keeps its bits: a grid's slower parameters keep their value for many rows.
struct CsvNumberMemo {
  std::uint64_t bits = 0;  ///< The number's bits.
  bool set = false;        ///< A number is remembered.
  unsigned char size = 0;  ///< Characters of its text.
  char text[32];           ///< Its text (`size` characters).
};

/// The text AppendCsvNumber writes for `value` (empty for NaN or an infinity), from *memo when
/// `value` has the bits *memo remembers, and remembered there otherwise. Valid until *memo
/// changes.
std::string_view CsvNumberText(double value, CsvNumberMemo* memo);

/// Writes CSV rows value by value into a string: fields separated by commas, each row ended
/// by LF ("\n"). The caller writes exactly one value per column, in column order.
class CsvRowWriter {
 public:
  /// Writes into `out` (appends; not owned).
  explicit CsvRowWriter(std::string* out) : out_(out) {}
  /// A number, shortest round-trip (AppendCsvNumber).
  void Number(double value);
  /// Number(value), its text taken from *memo when `value` has the bits *memo remembers, and
  /// remembered there otherwise (the same characters either way).
  void Number(double value, CsvNumberMemo* memo);
  /// An integer, in decimal.
  void Integer(std::int64_t value);
  /// An unsigned integer, in decimal.
  void Unsigned(std::uint64_t value);
  /// true or false.
  void Bool(bool value);
  /// A string, quoted when it must be (AppendCsvField).
  void String(std::string_view value);
  /// An empty field: the row has no value in this column.
  void Empty();
  /// Ends the row with LF.
  void EndRow();

 private:
  void Separate();
  std::string* out_;
  bool first_ = true;
};

/// Appends the header row: the columns' paths as written.
void AppendCsvHeader(const std::vector<ExploreColumn>& columns, std::string* out);

/// Appends one row: each column's value in `row` (a number as AppendCsvNumber, a string as
/// AppendCsvField, true/false; an object or array as its compact JSON text, quoted; null or
/// missing as an empty field).
void AppendCsvRow(const nlohmann::json& row, const std::vector<ExploreColumn>& columns,
                  std::string* out);

}  // namespace sweetspot::api
