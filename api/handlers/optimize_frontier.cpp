// POST /v1/optimize with "frontier": the best design at every value of one constraint (the
// best exit speed at every weight), one optimisation per value, each started from its
// neighbour's answer (core::OptimizeFrontier). Answered as JSON ({"rows", "pareto", "summary"}),
// or streamed as NDJSON (a row per value, then the summary line) or CSV (a row per value), as
// /v1/explore answers; "shard" takes a contiguous block of the values.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "api/error_code.hpp"
#include "api/handlers/endpoint.hpp"
#include "api/handlers/handlers.hpp"
#include "api/handlers/optimize_request.hpp"
#include "api/trade_units.hpp"
#include "core/optimize/frontier.hpp"

namespace sweetspot::api::optimize_detail {
namespace {

using Json = nlohmann::json;

// A parsed frontier request: the design problem of /v1/optimize and the frontier's own fields.
struct FrontierRequest {
  OptimizeRequest base;
  core::FrontierSpec spec;
  std::string written;  // the constraint as the request wrote it ("mass_oz")
  double to_si = 1.0;   // SI = written value * to_si
  std::vector<double> written_values;  // the shard's values as written (the rows give these)
  bool prefer_smaller = true;
  std::string format = "json";
  std::size_t first_index = 0;  // the shard's first value's index among all values
  std::size_t total_values = 0;
  bool imperial = false;
  Json provenance;
};

// "constraint": a FrontierQuantity's name, or a trade spelling of one ("mass_oz").
bool ReadQuantity(ObjectReader& reader, FrontierRequest* out) {
  std::string name;
  if (!reader.String("constraint", &name)) return false;
  if (const auto q = core::ParseFrontierQuantity(name)) {
    out->spec.quantity = *q;
    out->written = name;
    out->to_si = 1.0;
    return true;
  }
  for (const TradeForm& si : SiFormsOf(name)) {
    if (const auto q = core::ParseFrontierQuantity(si.key)) {
      out->spec.quantity = *q;
      out->written = name;
      out->to_si = si.to_si;
      return true;
    }
  }
  return reader.Fail("constraint",
                     "must name length_m, mass_kg, balance_point_m, moi_six_inch_kg_m2, "
                     "min_frequency_hz, max_barrel_diameter_m (or a trade form: length_in, "
                     "mass_oz, balance_point_in, moi_six_inch_oz_in2, max_barrel_diameter_in) or "
                     "swing_weight_exponent");
}

// "values": [v, ...] or "from", "to", "count" (count >= 2 values evenly spaced, ends included),
// in the constraint's written unit.
bool ReadValues(ObjectReader& reader, const ApiLimits& limits, FrontierRequest* out) {
  std::vector<double> values;
  if (const Json* list = reader.Get("values")) {
    if (!list->is_array()) return reader.Fail("values", "must be an array of numbers");
    if (list->size() > limits.max_frontier_values) {
      return reader.Fail("values",
                         "gives " + std::to_string(list->size()) +
                             " values, over the limit max_frontier_values = " +
                             std::to_string(limits.max_frontier_values) +
                             " (--max-frontier-values)",
                         ErrorCode::kTooBig);
    }
    for (std::size_t i = 0; i < list->size(); ++i) {
      if (!(*list)[i].is_number()) {
        return reader.Fail("values", "must be an array of numbers (item " + std::to_string(i) +
                                         " is not one)");
      }
      values.push_back((*list)[i].get<double>());
    }
    if (reader.Get("from") != nullptr || reader.Get("to") != nullptr ||
        reader.Get("count") != nullptr) {
      return reader.Fail("values", "give values or from/to/count, not both");
    }
  } else {
    double from = 0.0, to = 0.0;
    long long count = 0;
    reader.Number("from", AnyNumber(), &from);
    reader.Number("to", AnyNumber(), &to);
    if (!reader.ok()) return false;
    if (reader.Get("count") == nullptr) return reader.Missing("count");
    reader.OptionalInteger("count", 2, static_cast<long long>(limits.max_frontier_values), &count);
    if (!reader.ok()) return false;
    for (long long i = 0; i < count; ++i) {
      values.push_back(i + 1 == count ? to : from + (to - from) * i / (count - 1.0));
    }
  }
  out->written_values = values;
  for (double& v : values) v *= out->to_si;
  out->spec.values = std::move(values);
  return true;
}

bool ReadFrontier(const Json& value, const ApiLimits& limits, FrontierRequest* out,
                  ApiError* error) {
  ObjectReader reader(value, "frontier", error);
  if (!value.is_object()) return reader.Fail("", "must be an object");
  if (!ReadQuantity(reader, out) || !ReadValues(reader, limits, out)) return false;
  std::string bound = "equal", prefer = "smaller", continuation = "nlopt_slsqp";
  reader.OptionalString("bound", &bound, {"equal", "max", "min"});
  reader.OptionalString("prefer", &prefer, {"smaller", "larger"});
  reader.OptionalBool("warm_start", &out->spec.warm_start);
  reader.OptionalString("continuation", &continuation, {"nlopt_slsqp", "none"});
  if (!reader.Finish()) return false;
  out->spec.bound = bound == "max"   ? core::FrontierBound::kAtMost
                    : bound == "min" ? core::FrontierBound::kAtLeast
                                     : core::FrontierBound::kEqual;
  out->prefer_smaller = prefer == "smaller";
  out->spec.max_values = static_cast<int>(
      std::min<std::size_t>(limits.max_frontier_values, 1u << 30));
  return true;
}

// The request's constraint block may not also give the frontier's quantity (which value would
// hold?).
bool RefuseSecondForm(const Json& body, const FrontierRequest& r, ApiError* error) {
  const std::string si = core::FrontierQuantityName(r.spec.quantity);
  const Json* constraints = body.contains("constraints") ? &body["constraints"] : nullptr;
  if (constraints == nullptr || !constraints->is_object()) return true;
  std::vector<std::string> forms{si};
  for (const TradeForm& t : TradeForms(si)) forms.push_back(t.key);
  for (const std::string& form : forms) {
    if (constraints->contains(form)) {
      SetError(error, ErrorCode::kInvalidValue, "constraints." + form, &(*constraints)[form],
               "is the frontier's constraint (frontier.constraint = " + r.written +
                   "): leave it out, the frontier sets it at each value");
      return false;
    }
  }
  return true;
}

std::optional<FrontierRequest> ParseFrontierRequest(Json body, const Context& context,
                                                    ApiError* error) {
  FrontierRequest r;
  ReportUnits units = ReportUnits::kSi;
  if (!TakeReportUnits(&body, &units, error)) return std::nullopt;
  r.imperial = units == ReportUnits::kImperial;
  ObjectReader top(body, "", error);
  if (!ReadFrontier(body["frontier"], context.limits, &r, error)) return std::nullopt;
  top.OptionalString("format", &r.format, {"json", "ndjson", "csv"});
  struct {
    std::uint64_t index = 0, count = 1;
  } shard;
  if (const Json* s = top.Get("shard")) {
    ObjectReader sr(*s, "shard", error);
    long long index = 0, count = 1;
    sr.OptionalInteger("index", 0, (1LL << 40) - 1, &index);
    sr.OptionalInteger("count", 1, 1LL << 40, &count);
    if (!sr.Finish()) return std::nullopt;
    if (index >= count) {
      SetError(error, ErrorCode::kInvalidValue, "shard.index", &(*s)["index"],
               "must be below shard.count = " + std::to_string(count));
      return std::nullopt;
    }
    shard.index = static_cast<std::uint64_t>(index);
    shard.count = static_cast<std::uint64_t>(count);
  }
  if (!top.ok() || !RefuseSecondForm(body, r, error)) return std::nullopt;
  // The sweep's identity (as /v1/explore's): the request without shard, format, report_units.
  Json identity = body;
  identity.erase("shard");
  identity.erase("format");
  r.provenance = Provenance(identity, BodyOptions(body).options, std::nullopt);
  Json design = std::move(body);
  design.erase("frontier");
  design.erase("format");
  design.erase("shard");
  std::optional<OptimizeRequest> base = ParseOptimize(design, context, error);
  if (!base) return std::nullopt;
  r.base = std::move(*base);
  if (!r.base.material_choices.empty()) {
    SetError(error, ErrorCode::kInvalidValue, "variables", nullptr,
             "a frontier takes no material choice (one frontier per material: send one request "
             "each)");
    return std::nullopt;
  }
  if (core::Refusal refusal; !r.spec.Validate(r.base.problem, &refusal)) {
    CoreRefusal(refusal, "", error);
    return std::nullopt;
  }
  // The shard's contiguous block of values: shard i of n takes [i N / n, (i + 1) N / n).
  r.total_values = r.spec.values.size();
  const std::uint64_t n = r.total_values;
  const std::size_t from = static_cast<std::size_t>(shard.index * n / shard.count);
  const std::size_t to = static_cast<std::size_t>((shard.index + 1) * n / shard.count);
  r.first_index = from;
  const auto block = [from, to](const std::vector<double>& all) {
    return std::vector<double>(all.begin() + static_cast<std::ptrdiff_t>(from),
                               all.begin() + static_cast<std::ptrdiff_t>(to));
  };
  r.spec.values = block(r.spec.values);
  r.written_values = block(r.written_values);
  if (r.spec.values.empty()) {
    SetError(error, ErrorCode::kInvalidValue, "shard.count", nullptr,
             "leaves shard " + std::to_string(shard.index) + " no value (" +
                 std::to_string(n) + " values in " + std::to_string(shard.count) + " shards)");
    return std::nullopt;
  }
  return r;
}

// One value's row: its index among all values, the value as written, how it was started, and
// the design's answer as /v1/optimize gives it.
Json RowOf(const FrontierRequest& r, const core::FrontierPoint& point) {
  Json row = ResultToJson(point.result, r.base.request_bat, r.base.variable_names);
  Json out{{"index", r.first_index + static_cast<std::size_t>(point.index)},
           {r.written, r.written_values[static_cast<std::size_t>(point.index)]},
           {"start",
            {{"warm_started", point.warm_started},
             {"predicted", point.predicted},
             {"continued", point.continued},
             {"restarted", point.restarted}}}};
  for (auto& [key, value] : row.items()) out[key] = std::move(value);
  if (r.imperial) AddImperial(&out);
  return out;
}

Json SummaryOf(const FrontierRequest& r, const core::FrontierSummary& s, double timing_s) {
  Json pareto = Json::array();
  for (int i : s.pareto) pareto.push_back(r.first_index + static_cast<std::size_t>(i));
  return {{"termination", core::TerminationName(s.summary.termination)},
          {"message", s.summary.message},
          {"constraint", r.written},
          {"bound", core::FrontierBoundName(r.spec.bound)},
          {"prefer", r.prefer_smaller ? "smaller" : "larger"},
          {"objective", r.base.objective},
          {"values", r.total_values},
          {"points", s.points},
          {"converged", s.converged},
          {"continued", s.continued},
          {"restarts", s.restarts},
          {"first_index", r.first_index},
          {"pareto", std::move(pareto)},
          {"iterations", s.summary.iterations},
          {"evaluations", s.summary.evaluations},
          {"solve_time_s", Finite(s.summary.solve_time_s)},
          {"timing_s", timing_s},
          {"provenance", r.provenance}};
}

std::string CompactText(const Json& value) {
  return value.dump(-1, ' ', false, Json::error_handler_t::replace);
}

// A CSV field: a number or bool as JSON writes it, a string quoted when it needs it, null empty.
void AppendCsvField(const Json& v, std::string* line) {
  if (v.is_null()) return;
  if (!v.is_string()) {
    *line += CompactText(v);
    return;
  }
  const std::string& s = v.get_ref<const std::string&>();
  if (s.find_first_of(",\"\n\r") == std::string::npos) {
    *line += s;
    return;
  }
  line->push_back('"');
  for (char c : s) {
    if (c == '"') line->push_back('"');
    line->push_back(c);
  }
  line->push_back('"');
}

// The CSV's columns: JSON pointers into a row, named by their path.
std::vector<std::string> CsvColumns(const FrontierRequest& r) {
  std::vector<std::string> columns{"index",
                                   r.written,
                                   "summary.termination",
                                   "objective_value",
                                   "objective_unit",
                                   "summary.iterations",
                                   "summary.evaluations",
                                   "summary.solve_time_s",
                                   "summary.backend",
                                   "start.continued",
                                   "properties.mass_kg",
                                   "properties.balance_point_m",
                                   "properties.moi_six_inch_kg_m2",
                                   "properties.length_m",
                                   "sweet_spot.position_from_knob_m",
                                   "sweet_spot.exit_speed_mps"};
  for (const core::DesignVariable& v : r.base.problem.variables) {
    const WrittenVariable* written = r.base.variable_names.Find(v.path);
    columns.push_back("variables." + (written != nullptr ? written->written : v.path));
  }
  return columns;
}

// The value at a column's path: a top-level key, or "<block>.<key>" one level down (a variable
// "profile.knots[3].radius_m" keeps its dots: only the first dot splits).
const Json* At(const Json& row, const std::string& path) {
  const auto top = row.find(path);
  if (top != row.end()) return &*top;
  const std::size_t dot = path.find('.');
  if (dot == std::string::npos) return nullptr;
  const auto block = row.find(path.substr(0, dot));
  if (block == row.end() || !block->is_object()) return nullptr;
  const auto value = block->find(path.substr(dot + 1));
  return value == block->end() ? nullptr : &*value;
}

// With "report_units": "imperial", each SI column followed by its twins that the row (an
// AddImperial'd row) has: "objective_value" -> "objective_value_mph" (or "_in", "_ft" for a
// carry), "properties.mass_kg" -> "properties.mass_oz", "sweet_spot.position_from_knob_m" ->
// "..._in", "sweet_spot.position_from_tip_in". A variable's column stays as written.
std::vector<std::string> WithImperialTwins(const std::vector<std::string>& columns,
                                           const Json& row) {
  std::vector<std::string> out;
  for (const std::string& column : columns) {
    out.push_back(column);
    if (column.rfind("variables.", 0) == 0) continue;
    const std::size_t dot = column.find('.');
    const std::string prefix = dot == std::string::npos ? "" : column.substr(0, dot + 1);
    const Json* block = &row;
    if (dot != std::string::npos) {
      const auto it = row.find(column.substr(0, dot));
      if (it == row.end() || !it->is_object()) continue;
      block = &*it;
    }
    for (const std::string& twin : ImperialTwinKeys(*block, column.substr(prefix.size()))) {
      if (block->contains(twin)) out.push_back(prefix + twin);
    }
  }
  return out;
}

std::string CsvHeader(const std::vector<std::string>& columns) {
  std::string header;
  for (std::size_t i = 0; i < columns.size(); ++i) {
    if (i > 0) header.push_back(',');
    AppendCsvField(Json(columns[i]), &header);
  }
  header.push_back('\n');
  return header;
}

std::string CsvLine(const Json& row, const std::vector<std::string>& columns) {
  std::string line;
  for (std::size_t i = 0; i < columns.size(); ++i) {
    if (i > 0) line.push_back(',');
    if (const Json* v = At(row, columns[i])) AppendCsvField(*v, &line);
  }
  line.push_back('\n');
  return line;
}

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

Json ErrorLine(ErrorCode code, const std::string& message) {
  return {{"error", {{"code", ErrorCodeName(code)}, {"message", message}, {"field", nullptr}}}};
}

}  // namespace

Response HandleFrontier(Json body, const Context& context,
                        std::chrono::steady_clock::time_point start) {
  ApiError error;
  std::optional<FrontierRequest> parsed = ParseFrontierRequest(std::move(body), context, &error);
  if (!parsed) return ToResponse(error);
  if (context.validate_only) return ValidRequest();
  auto request = std::make_shared<const FrontierRequest>(std::move(*parsed));
  core::Progress* progress = context.progress;
  const auto run = [request, progress](const core::FrontierSink& sink) {
    return core::OptimizeFrontier(request->base.problem, request->spec, request->base.options,
                                  request->prefer_smaller, sink, progress);
  };
  if (request->format == "csv") {
    Response streamed = Response::Text(200, std::string(), "text/csv");
    streamed.stream = [request, run](const ChunkSink& sink) {
      std::vector<std::string> columns = CsvColumns(*request);
      // In SI the header goes out at once; in imperial units with the first row, whose twins
      // (the objective's unit among them) name the extra columns.
      bool header_sent = !request->imperial;
      if (header_sent && !sink(CsvHeader(columns))) return false;
      const core::FrontierSummary s = run([&](const core::FrontierPoint& point) {
        const Json row = RowOf(*request, point);
        if (!header_sent) {
          columns = WithImperialTwins(columns, row);
          header_sent = true;
          if (!sink(CsvHeader(columns))) return false;
        }
        return sink(CsvLine(row, columns));
      });
      if (!header_sent && !sink(CsvHeader(columns))) return false;  // no row at all
      return !s.stopped && !s.cancelled && s.summary.termination != core::Termination::kFailure;
    };
    return streamed;
  }
  if (request->format == "ndjson") {
    Response streamed = Response::Text(200, std::string(), "application/x-ndjson");
    streamed.stream = [request, run, start](const ChunkSink& sink) {
      const core::FrontierSummary s = run([&](const core::FrontierPoint& point) {
        return sink(CompactText(RowOf(*request, point)) + "\n");
      });
      if (s.stopped) return false;
      if (s.cancelled) {
        sink(CompactText(ErrorLine(ErrorCode::kCancelled, s.summary.message)) + "\n");
        return false;
      }
      if (s.summary.termination == core::Termination::kFailure) {
        sink(CompactText(ErrorLine(ErrorCode::kModelFailed, s.summary.message)) + "\n");
        return false;
      }
      return sink(CompactText({{"summary", SummaryOf(*request, s, SecondsSince(start))}}) + "\n");
    };
    return streamed;
  }
  Json rows = Json::array();
  const core::FrontierSummary s =
      run([&](const core::FrontierPoint& point) {
        rows.push_back(RowOf(*request, point));
        return true;
      });
  if (s.cancelled) return ErrorResponse(409, ErrorCode::kCancelled, s.summary.message);
  if (s.summary.termination == core::Termination::kFailure) {
    return ErrorResponse(500, ErrorCode::kModelFailed, s.summary.message);
  }
  return {200, {{"rows", std::move(rows)}, {"summary", SummaryOf(*request, s, SecondsSince(start))}}};
}

}  // namespace sweetspot::api::optimize_detail
