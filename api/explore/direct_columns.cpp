#include "api/explore/direct_columns.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <charconv>
#include <cmath>
#include <condition_variable>
#include <cstring>
#include <exception>
#include <map>
#include <mutex>
#include <new>
#include <string_view>
#include <system_error>
#include <thread>
#include <utility>
#include "api/bat_json.hpp"
#include "api/json_reader.hpp"
#include "api/memory_reserve.hpp"
#include "api/scene_json.hpp"
#include "api/trade_units.hpp"
#include "core/numerics/timing_book.hpp"

namespace sweetspot::api::explore_direct {

std::optional<DirectAccessor> CompileSiAccessor(const std::vector<std::string>& tokens,
                                                const std::vector<SweepParameter>& parameters,
                                                const RowOutputs& outputs);

bool IsNumberSource(const DirectAccessor& a) {
  if (a.source == Source::kOutputField) return a.field->number;
  switch (a.source) {
    case Source::kIndex:
    case Source::kFeasible:
    case Source::kParameter:
    case Source::kMissing:
    case Source::kInertiaModel:
      return false;
    default:
      return true;
  }
}

// The accessor of `tokens` in a feasible row of this sweep, or nullopt when the engine does
// not read it directly (the row is then rendered as JSON). A field of an output block may be
// named in a trade unit, as "report_units": "imperial" adds it (AddImperialToRow): its SI
// field's accessor with the conversion AddImperial makes, so the number is the same bits.
std::optional<DirectAccessor> CompileAccessor(const std::vector<std::string>& tokens,
                                              const std::vector<SweepParameter>& parameters,
                                              const RowOutputs& outputs) {
  if (auto native = CompileSiAccessor(tokens, parameters, outputs)) return native;
  if (tokens.size() < 2 || tokens[0] == "parameters" || tokens[0] == "error") return std::nullopt;
  for (const ImperialSource& source : ImperialSources(tokens.back())) {
    std::vector<std::string> si = tokens;
    si.back() = source.si_key;
    auto accessor = CompileSiAccessor(si, parameters, outputs);
    if (!accessor || !IsNumberSource(*accessor)) continue;
    accessor->convert = source.from_tip ? DirectConvert::kFromTip : DirectConvert::kDivide;
    accessor->factor = source.to_si;
    return accessor;
  }
  return std::nullopt;
}

// The accessor of SI (or native) field `tokens` in a feasible row of this sweep, or nullopt.
// The names are those RenderDesignRow renders (SceneResultToJson, PropertiesToJson):
// explore_engine_test checks every one of them against the JSON row.
std::optional<DirectAccessor> CompileSiAccessor(const std::vector<std::string>& tokens,
                                                const std::vector<SweepParameter>& parameters,
                                                const RowOutputs& outputs) {
  using S = Source;
  const auto has = [&outputs](core::SceneOutput o) {
    return std::find(outputs.scene.begin(), outputs.scene.end(), o) != outputs.scene.end();
  };
  const auto field = [&tokens](const std::map<std::string_view, S>& table) -> std::optional<S> {
    if (tokens.size() != 2) return std::nullopt;
    const auto it = table.find(tokens[1]);
    if (it == table.end()) return std::nullopt;
    return it->second;
  };
  if (tokens.empty()) return std::nullopt;
  const std::string& head = tokens[0];
  std::optional<S> source;
  if (tokens.size() == 1 && head == "index") {
    source = S::kIndex;
  } else if (tokens.size() == 1 && head == "feasible") {
    source = S::kFeasible;
  } else if (tokens.size() == 2 && head == "parameters") {
    for (std::size_t k = 0; k < parameters.size(); ++k) {
      if (parameters[k].path == tokens[1]) return DirectAccessor{S::kParameter, k};
    }
  } else if (head == "error") {
    source = S::kMissing;  // a feasible row has no error
  } else if (tokens.size() == 1 && head == "collision_efficiency" && outputs.collision_efficiency) {
    source = S::kCollisionEfficiency;
  } else if (const auto output = core::ParseSceneOutput(head); output && has(*output)) {
    // A field of a requested output's block that its declaration reads directly.
    if (tokens.size() != 2) return std::nullopt;
    const ApiOutputDecl& decl = ApiOutputDeclaration(*output);
    for (const DirectField* f = decl.direct_begin; f != decl.direct_end; ++f) {
      if (tokens[1] == f->name) {
        DirectAccessor accessor{S::kOutputField, 0};
        accessor.field = f;
        return accessor;
      }
    }
    return std::nullopt;
  } else if (head == "properties" && outputs.properties) {
    if (tokens.size() == 3 && tokens[1] == "imperial") {
      static const std::map<std::string_view, S> kImperial = {
          {"length_in", S::kLengthIn},
          {"weight_oz", S::kWeightOz},
          {"drop", S::kDrop},
          {"balance_point_in", S::kBalanceIn},
          {"moi_knob_oz_in2", S::kMoiKnobOzIn2},
          {"moi_six_inch_oz_in2", S::kMoiSixInchOzIn2},
          {"moi_centroid_oz_in2", S::kMoiCentroidOzIn2}};
      if (const auto it = kImperial.find(tokens[2]); it != kImperial.end()) source = it->second;
    } else {
      source = field({{"mass_kg", S::kMass},
                      {"balance_point_m", S::kBalance},
                      {"moi_knob_kg_m2", S::kMoiKnob},
                      {"moi_six_inch_kg_m2", S::kMoiSixInch},
                      {"moi_centroid_kg_m2", S::kMoiCentroid},
                      {"volume_m3", S::kVolume},
                      {"length_m", S::kLength},
                      {"inertia_model", S::kInertiaModel}});
    }
  }
  if (!source) return std::nullopt;
  return DirectAccessor{*source, 0};
}

DirectView ViewOf(const DesignOutcome& o) {
  const core::SceneResult& r = o.result;
  DirectView v;
  v.properties = &r.mass_properties;
  v.length_m = r.length_m;
  v.collision_efficiency = &o.collision_efficiency;
  v.outputs.result = &r;
  return v;
}

// The lean path's design: max_exit_speed by the closed form of the model named `model_name`.
DirectView ViewOf(const core::ClosedFormDesign& d, std::string_view model_name) {
  DirectView v;
  v.properties = &d.mass_properties;
  v.length_m = d.length_m;
  v.outputs.lean = &d;
  v.outputs.lean_model = model_name;
  return v;
}

DirectValue ReadSiDirect(const DirectAccessor& a, std::uint64_t index,
                         const std::vector<double>& values, const DirectView& o,
                         const core::ImperialProperties& imperial);

// The value of `a` in the feasible row of design `index`.
DirectValue ReadDirect(const DirectAccessor& a, std::uint64_t index,
                       const std::vector<double>& values, const DirectView& o,
                       const core::ImperialProperties& imperial) {
  DirectValue d = ReadSiDirect(a, index, values, o, imperial);
  if (a.convert == DirectConvert::kNone || d.kind != DirectValue::kNumber) return d;
  // As AddImperial computes it (api/trade_units.cpp), operation for operation.
  d.number = a.convert == DirectConvert::kDivide ? d.number / a.factor
                                                 : (o.length_m - d.number) / a.factor;
  return d;
}

// The value of `a`'s SI field in the feasible row of design `index`.
DirectValue ReadSiDirect(const DirectAccessor& a, std::uint64_t index,
                         const std::vector<double>& values, const DirectView& o,
                         const core::ImperialProperties& imperial) {
  using S = Source;
  const core::MassProperties& p = *o.properties;
  switch (a.source) {
    case S::kIndex: {
      DirectValue d;
      d.kind = DirectValue::kUnsigned;
      d.count = index;
      return d;
    }
    case S::kFeasible: {
      DirectValue d;
      d.kind = DirectValue::kBool;
      d.flag = true;
      return d;
    }
    case S::kParameter:
      return Number(values[a.parameter]);
    case S::kMissing:
      return {};
    case S::kCollisionEfficiency:
      return o.collision_efficiency != nullptr && o.collision_efficiency->has_value()
                 ? Number(**o.collision_efficiency)
                 : DirectValue{};
    case S::kOutputField:
      return a.field->read(o.outputs);
    case S::kMass:
      return Number(p.mass_kg);
    case S::kBalance:
      return Number(p.balance_point_m);
    case S::kMoiKnob:
      return Number(p.moi_knob_kg_m2);
    case S::kMoiSixInch:
      return Number(p.MoiSixInchKgM2());
    case S::kMoiCentroid:
      return Number(p.moi_centroid_kg_m2);
    case S::kVolume:
      return Number(p.volume_m3);
    case S::kLength:
      return Number(o.length_m);
    case S::kInertiaModel:
      return Text(InertiaModelName(p.inertia_model));
    case S::kLengthIn:
      return Number(imperial.length_in);
    case S::kWeightOz:
      return Number(imperial.weight_oz);
    case S::kDrop:
      return Number(imperial.drop);
    case S::kBalanceIn:
      return Number(imperial.balance_point_in);
    case S::kMoiKnobOzIn2:
      return Number(imperial.moi_knob_oz_in2);
    case S::kMoiSixInchOzIn2:
      return Number(imperial.moi_six_inch_oz_in2);
    case S::kMoiCentroidOzIn2:
      return Number(imperial.moi_centroid_oz_in2);
  }
  return {};
}

bool NeedsImperial(const std::vector<DirectAccessor>& accessors) {
  return std::any_of(accessors.begin(), accessors.end(), [](const DirectAccessor& a) {
    return a.source >= Source::kLengthIn && a.source <= Source::kMoiCentroidOzIn2;
  });
}

Json ToJson(const DirectValue& v) {
  switch (v.kind) {
    case DirectValue::kMissing:
      return nullptr;
    case DirectValue::kNumber:
      return v.number;
    case DirectValue::kUnsigned:
      return v.count;
    case DirectValue::kBool:
      return v.flag;
    case DirectValue::kString:
      return std::string(v.text);
  }
  return nullptr;
}

double ToObjective(const DirectValue& v) {
  if (v.kind == DirectValue::kNumber) return v.number;
  if (v.kind == DirectValue::kUnsigned) return static_cast<double>(v.count);
  return std::nan("");
}

void WriteCsv(const DirectValue& v, CsvRowWriter* writer) {
  switch (v.kind) {
    case DirectValue::kMissing:
      writer->Empty();
      break;
    case DirectValue::kNumber:
      writer->Number(v.number);
      break;
    case DirectValue::kUnsigned:
      writer->Unsigned(v.count);
      break;
    case DirectValue::kBool:
      writer->Bool(v.flag);
      break;
    case DirectValue::kString:
      writer->String(v.text);
      break;
  }
}

std::string DumpRow(const Json& value) {
  return value.dump(-1, ' ', false, Json::error_handler_t::replace);
}

// Appends `v` as the serializer of DumpRow writes it (nlohmann's: its shortest round-trip text
// of a double, null for a missing value or a non-finite number, the string escaped).
void AppendJsonValue(const DirectValue& v, JsonValueMemo* memo, std::string* out) {
  switch (v.kind) {
    case DirectValue::kMissing:
      out->append("null");
      return;
    case DirectValue::kUnsigned: {
      char buffer[24];
      out->append(buffer, std::to_chars(buffer, buffer + sizeof(buffer), v.count).ptr);
      return;
    }
    case DirectValue::kBool:
      out->append(v.flag ? "true" : "false");
      return;
    case DirectValue::kNumber: {
      std::uint64_t bits = 0;
      std::memcpy(&bits, &v.number, sizeof bits);
      if (memo->kind != DirectValue::kNumber || memo->bits != bits) {
        memo->kind = DirectValue::kNumber;
        memo->bits = bits;
        char* const begin = memo->number.data();
        if (!std::isfinite(v.number)) {
          std::memcpy(begin, "null", 4);
          memo->number_size = 4;
        } else {
          // What basic_json's serializer calls for a double (dump_float), in its buffer size.
          const char* end =
              nlohmann::detail::to_chars(begin, begin + memo->number.size(), v.number);
          memo->number_size = static_cast<std::size_t>(end - begin);
        }
      }
      out->append(memo->number.data(), memo->number_size);
      return;
    }
    case DirectValue::kString:
      if (memo->kind != DirectValue::kString || memo->source != v.text) {
        memo->kind = DirectValue::kString;
        memo->source.assign(v.text);
        memo->text = DumpRow(Json(memo->source));
      }
      out->append(memo->text);
      return;
  }
}

// What one run of a sweep shares between its threads: the format, the compiled columns and
// objectives, the designs.

}  // namespace sweetspot::api::explore_direct
