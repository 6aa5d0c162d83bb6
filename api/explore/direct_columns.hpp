// The direct columns of a sweep: the values a column or objective reads straight from a design's
// outcome (DesignOutcome, or a closed-form design) without rendering its JSON row, and how they
// are written as JSON, CSV or an objective. Internal to the sweep engine (api/explore/engine.cpp);
// ExploreEngineTest checks every name against the JSON path.
#pragma once

#include <nlohmann/json.hpp>

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "api/explore/binder.hpp"
#include "api/explore/columns.hpp"
#include "api/explore/engine.hpp"
#include "api/outputs/scene_outputs.hpp"
#include "core/scene/closed_form_designs.hpp"

namespace sweetspot::api::explore_direct {

using Json = nlohmann::json;

// A value a column reads from a design's outcome without a JSON row (api/outputs/).
using ::sweetspot::api::DirectValue;
using ::sweetspot::api::Number;
using ::sweetspot::api::Text;

// Where a direct column's value comes from.
enum class Source {
  kIndex,
  kFeasible,
  kParameter,
  kMissing,
  kCollisionEfficiency,
  kOutputField,  // a field of a scene output's block: its declaration's DirectField
  kMass,
  kBalance,
  kMoiKnob,
  kMoiSixInch,
  kMoiCentroid,
  kVolume,
  kLength,
  kInertiaModel,
  kLengthIn,
  kWeightOz,
  kDrop,
  kBalanceIn,
  kMoiKnobOzIn2,
  kMoiSixInchOzIn2,
  kMoiCentroidOzIn2,
};

// How a direct value is turned into the trade-unit field a column names (ImperialSources).
enum class DirectConvert {
  kNone,     // the value as it is
  kDivide,   // value / factor ("exit_speed_mph")
  kFromTip,  // (bat length - value) / inch ("position_from_tip_in")
};

struct DirectAccessor {
  Source source = Source::kMissing;
  std::size_t parameter = 0;
  const DirectField* field = nullptr;  // kOutputField: the output's field
  DirectConvert convert = DirectConvert::kNone;
  double factor = 1.0;  // kDivide's divisor
};

// The accessor of `tokens` in a feasible row of this sweep, or nullopt when the engine does
// not read it directly (the row is then rendered as JSON). A field of an output block may be
// named in a trade unit, as "report_units": "imperial" adds it (AddImperialToRow): its SI
// field's accessor with the conversion AddImperial makes, so the number is the same bits.
std::optional<DirectAccessor> CompileAccessor(const std::vector<std::string>& tokens,
                                              const std::vector<SweepParameter>& parameters,
                                              const RowOutputs& outputs);

// What a direct column reads of a feasible design: a DesignOutcome's result, or the lean
// path's numbers (core::ClosedFormDesign), the same fields under the same names.
struct DirectView {
  const core::MassProperties* properties = nullptr;
  double length_m = 0.0;
  const std::optional<double>* collision_efficiency = nullptr;  // null: none
  OutputView outputs;  // what the scene outputs' direct fields read
};

// What a direct column reads of a design evaluated in full.
DirectView ViewOf(const DesignOutcome& o);

// The lean path's design: max_exit_speed by the closed form of the model named `model_name`.
DirectView ViewOf(const core::ClosedFormDesign& d, std::string_view model_name);

// The value of `a` in the feasible row of design `index`.
DirectValue ReadDirect(const DirectAccessor& a, std::uint64_t index,
                       const std::vector<double>& values, const DirectView& o,
                       const core::ImperialProperties& imperial);

// True when some accessor reads a trade-unit property (the row then computes them once).
bool NeedsImperial(const std::vector<DirectAccessor>& accessors);

// The value as the JSON row holds it (null when missing).
Json ToJson(const DirectValue& v);

// The value as an objective reads it (NaN when it is not a number).
double ToObjective(const DirectValue& v);

// Writes the value as the next CSV field.
void WriteCsv(const DirectValue& v, CsvRowWriter* writer);

// A JSON row's text, as every sweep format writes it.
std::string DumpRow(const Json& value);

// The JSON text of the last number or string one column wrote, reused while the value stays
// the same: a grid's slower parameters keep their value for many rows.
struct JsonValueMemo {
  DirectValue::Kind kind = DirectValue::kMissing;  // kMissing: nothing remembered
  std::uint64_t bits = 0;                          // kNumber: the number's bits
  std::string source;                              // kString: the string
  std::string text;                                // kString: its JSON text
  std::array<char, 64> number;                     // kNumber: its JSON text, number_size long
  std::size_t number_size = 0;
};

// Appends `v` as the serializer of DumpRow writes it (nlohmann's: its shortest round-trip text
// of a double, null for a missing value or a non-finite number, the string escaped).
void AppendJsonValue(const DirectValue& v, JsonValueMemo* memo, std::string* out);

}  // namespace sweetspot::api::explore_direct
