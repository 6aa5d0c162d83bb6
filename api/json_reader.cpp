#include "api/json_reader.hpp"

#include "api/trade_units.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "core/geometry_format.hpp"

namespace sweetspot::api {
namespace {

// The optimal-string-alignment distance of `a` and `b` (insertions, deletions,
// substitutions and swaps of two neighbours each count 1), or limit + 1 once it exceeds
// `limit`.
std::size_t TypoDistance(std::string_view a, std::string_view b, std::size_t limit) {
  if (a.size() > b.size() + limit || b.size() > a.size() + limit) return limit + 1;
  std::vector<std::vector<std::size_t>> d(a.size() + 1, std::vector<std::size_t>(b.size() + 1));
  for (std::size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
  for (std::size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) {
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
      }
    }
  }
  return std::min(d[a.size()][b.size()], limit + 1);
}

}  // namespace

std::string NearestName(std::string_view written, const std::vector<std::string>& names) {
  // One typo in a short name, two in a longer one: "masss_kg" -> "mass_kg",
  // "lenght_in" -> "length_in", but "x_m" is not "r_m"'s typo.
  const std::size_t limit = written.size() < 6 ? 1 : 2;
  std::string best;
  std::size_t best_distance = limit + 1;
  for (const std::string& name : names) {
    if (name == written) continue;
    const std::size_t distance = TypoDistance(written, name, limit);
    if (distance < best_distance) {
      best_distance = distance;
      best = name;
    }
  }
  return best;
}

namespace {

using Json = nlohmann::json;

// A DOM-building SAX parser that enforces depth, array and string limits as
// it reads, so a hostile body never builds a deep or huge value (pitfalls.md:
// destroying a value nested ~100,000 levels deep crashes nlohmann-json).
class LimitedSax : public nlohmann::detail::json_sax_dom_parser<Json> {
 public:
  using Base = nlohmann::detail::json_sax_dom_parser<Json>;
  LimitedSax(Json& target, const ApiLimits& limits, ApiError* error)
      : Base(target, /*allow_exceptions=*/false), limits_(limits), error_(error) {}

  bool null() { return Value() && Base::null(); }
  bool boolean(bool b) { return Value() && Base::boolean(b); }
  bool number_integer(Json::number_integer_t n) { return Value() && Base::number_integer(n); }
  bool number_unsigned(Json::number_unsigned_t n) { return Value() && Base::number_unsigned(n); }
  bool number_float(Json::number_float_t n, const Json::string_t& s) {
    if (!std::isfinite(n))
      return Refuse(400, ErrorCode::kInvalidValue, "number " + s + " is out of range");
    return Value() && Base::number_float(n, s);
  }
  bool string(Json::string_t& s) {
    if (s.size() > limits_.max_string_length) return TooLong("string", s.size());
    return Value() && Base::string(s);
  }
  bool binary(Json::binary_t& b) { return Value() && Base::binary(b); }
  bool key(Json::string_t& k) {
    if (k.size() > limits_.max_string_length) return TooLong("key", k.size());
    return Base::key(k);
  }
  bool start_object(std::size_t n) { return Open(false) && Base::start_object(n); }
  bool end_object() {
    containers_.pop_back();
    return Base::end_object();
  }
  bool start_array(std::size_t n) { return Open(true) && Base::start_array(n); }
  bool end_array() {
    containers_.pop_back();
    return Base::end_array();
  }
  bool parse_error(std::size_t position, const std::string& last_token,
                   const nlohmann::detail::exception& ex) {
    if (error_->code) return false;
    std::string what = ex.what();
    // "[json.exception.parse_error.101] parse error at line 1, column 2: ..." -> after "] ".
    if (const auto pos = what.find("] "); pos != std::string::npos) what = what.substr(pos + 2);
    if (ex.id == 406) {
      return Refuse(400, ErrorCode::kInvalidValue,
                    "number " + last_token + " is out of range of a double");
    }
    return Refuse(400, ErrorCode::kInvalidJson,
                  "body is not valid JSON at byte " + std::to_string(position) + ": " + what);
  }

 private:
  struct Container {
    bool is_array;
    std::size_t count;
  };

  bool Refuse(int status, ErrorCode code, std::string message) {
    if (!error_->code) *error_ = ApiError{status, code, std::move(message), ""};
    return false;
  }
  bool TooLong(const char* what, std::size_t size) {
    return Refuse(413, ErrorCode::kTooBig,
                  std::string("a ") + what + " of " + std::to_string(size) +
                      " bytes exceeds the limit max_string_length = " +
                      std::to_string(limits_.max_string_length) + " (--max-string-length)");
  }
  // Counts one value in the enclosing array.
  bool Value() {
    if (!containers_.empty() && containers_.back().is_array &&
        ++containers_.back().count > limits_.max_array_length) {
      return Refuse(413, ErrorCode::kTooBig,
                    "an array exceeds the limit max_array_length = " +
                        std::to_string(limits_.max_array_length) + " (--max-array-length)");
    }
    return true;
  }
  bool Open(bool is_array) {
    if (!Value()) return false;
    if (static_cast<int>(containers_.size()) >= limits_.max_json_depth) {
      return Refuse(413, ErrorCode::kTooBig,
                    "nesting exceeds the limit max_json_depth = " +
                        std::to_string(limits_.max_json_depth) + " (--max-json-depth)");
    }
    containers_.push_back({is_array, 0});
    return true;
  }

  const ApiLimits& limits_;
  ApiError* error_;
  std::vector<Container> containers_;
};

}  // namespace

Response ToResponse(const ApiError& error) {
  nlohmann::json body{{"code", ErrorCodeName(error.code.value_or(ErrorCode::kInternalError))},
                      {"message", error.message}};
  body["field"] = error.field.empty() ? nlohmann::json(nullptr) : nlohmann::json(error.field);
  return {error.status, std::move(body)};
}

std::optional<nlohmann::json> ParseBody(std::string_view body, const ApiLimits& limits,
                                        ApiError* error) {
  Json plain;
  if (ReadPlainBody(body, limits, &plain)) return plain;
  return ParseBodyWithNlohmann(body, limits, error);
}

std::optional<nlohmann::json> ParseBodyWithNlohmann(std::string_view body, const ApiLimits& limits,
                                                    ApiError* error) {
  const auto first = body.find_first_not_of(" \t\r\n");
  if (first == std::string_view::npos) return nlohmann::json::object();
  Json root;
  LimitedSax sax(root, limits, error);
  const bool ok = Json::sax_parse(body.begin(), body.end(), &sax);
  if (!ok || error->code) {
    if (!error->code) *error = ApiError{400, ErrorCode::kInvalidJson, "body is not valid JSON", ""};
    return std::nullopt;
  }
  return root;
}

std::string NumberRule::Describe() const {
  const bool has_min = min > -1e299;
  const bool has_max = max < 1e299;
  std::string kind = integer ? "an integer" : "a number";
  if (has_min && has_max) {
    return "must be " + kind + " in " + (min_exclusive ? "(" : "[") + core::FormatNumber(min) +
           ", " + core::FormatNumber(max) + (max_exclusive ? ")" : "]");
  }
  if (has_min)
    return "must be " + kind + (min_exclusive ? " > " : " >= ") + core::FormatNumber(min);
  if (has_max)
    return "must be " + kind + (max_exclusive ? " < " : " <= ") + core::FormatNumber(max);
  return "must be " + kind;
}

bool NumberRule::Accepts(double value) const {
  if (!std::isfinite(value)) return false;
  if (integer && std::floor(value) != value) return false;
  if (min_exclusive ? !(value > min) : !(value >= min)) return false;
  if (max_exclusive ? !(value < max) : !(value <= max)) return false;
  return true;
}

namespace {

// The rule's text for a value it refuses. Describe() leaves out a bound at the rule's default
// magnitude (+-1e300, which AnyNumber, Positive, NonNegative have): a finite value beyond it
// (1e301) was refused as "must be a number", which names no range. Such a value gets the
// whole interval, that bound included.
std::string DescribeRefusal(const NumberRule& rule, double value) {
  const bool beyond_default = std::isfinite(value) && ((value > rule.max && !(rule.max < 1e299)) ||
                                                       (value < rule.min && !(rule.min > -1e299)));
  if (!beyond_default) return rule.Describe();
  return std::string("must be ") + (rule.integer ? "an integer" : "a number") + " in " +
         (rule.min_exclusive ? "(" : "[") + core::FormatNumber(rule.min) + ", " +
         core::FormatNumber(rule.max) + (rule.max_exclusive ? ")" : "]");
}

}  // namespace

NumberRule AnyNumber() { return NumberRule{}; }
NumberRule Positive(double max) { return NumberRule{0.0, max, true, false, false}; }
NumberRule NonNegative(double max) { return NumberRule{0.0, max, false, false, false}; }
NumberRule Between(double min, double max) { return NumberRule{min, max, false, false, false}; }
NumberRule IntegerBetween(double min, double max) {
  return NumberRule{min, max, false, false, true};
}

std::string Show(const nlohmann::json& value) {
  std::string text = value.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  if (text.size() > 60) text = text.substr(0, 57) + "...";
  return text;
}

std::string JoinPath(std::string_view parent, std::string_view key) {
  if (parent.empty()) return std::string(key);
  return std::string(parent) + "." + std::string(key);
}

std::string RequestName(std::string_view core_field) {
  // Core's name -> the request's, only where the two differ. An entry ending in '.'
  // renames a head (every field below it); any other renames that one field.
  struct Renamed {
    std::string_view core;
    std::string_view request;
  };
  constexpr Renamed kRenamed[] = {
      {"hertz.paper.", "hertz.paper_constants."},
      {"flexible.impact.frequency_tolerance", "flexible.mode_frequency_tolerance"},
      {"ball.stiffness", "ball.stiffness_n_m_p"},
      {"constraints.max_taper_slope", "constraints.taper.max_slope"},
      {"constraints.taper_first_knot", "constraints.taper.first_knot"},
      {"constraints.taper_last_knot", "constraints.taper.last_knot"},
  };
  for (const Renamed& r : kRenamed) {
    const bool head = r.core.back() == '.';
    if (head ? core_field.substr(0, r.core.size()) == r.core : core_field == r.core) {
      return std::string(r.request) + std::string(core_field.substr(r.core.size()));
    }
  }
  return std::string(core_field);
}

namespace {

// `refusal` in the request's names. A design's rule set ("rules.mlb-wood", core's name) is
// an entry of the request's constraints.rules: the refusal quotes the set's name as its value.
core::Refusal InRequestNames(const core::Refusal& refusal) {
  core::Refusal out = refusal;
  constexpr std::string_view kRules = "rules.";
  const std::string_view field = refusal.field;
  if (field.substr(0, kRules.size()) == kRules &&
      field.find('.', kRules.size()) == std::string_view::npos && !refusal.QuotesValue()) {
    out.field = "constraints.rules";
    out.shown = "\"" + std::string(field.substr(kRules.size())) + "\"";
    return out;
  }
  out.field = RequestName(refusal.field);
  return out;
}

}  // namespace

std::string RequestField(const core::Refusal& refusal, std::string_view prefix) {
  return refusal.field.empty() ? std::string(prefix)
                               : JoinPath(prefix, InRequestNames(refusal).field);
}

std::string RequestMessage(const core::Refusal& refusal) {
  return InRequestNames(refusal).Message();
}

bool CoreRefusal(const core::Refusal& refusal, const std::string& prefix, ApiError* error) {
  if (error->code) return false;
  const std::string why = RequestMessage(refusal);
  std::string message;
  if (!refusal.field.empty()) {
    message = JoinPath(prefix, why);
  } else {
    message = prefix.empty() ? why : prefix + ": " + why;
  }
  *error =
      ApiError{400, ErrorCode::kInvalidValue, std::move(message), RequestField(refusal, prefix)};
  return false;
}

bool CoreRefusal(const core::Summary& summary, const std::string& prefix, ApiError* error) {
  if (summary.refusal.has_value()) return CoreRefusal(*summary.refusal, prefix, error);
  return CoreRefusal(core::TextRefusal("", summary.message), prefix, error);
}

bool IsSceneField(std::string_view core_field) {
  // The heads of core::Scene's fields; every other core field of a scene request is an option.
  constexpr std::string_view kSceneHeads[] = {
      "bat", "ball", "swing", "cor", "outputs", "inertia_model", "contact", "environment", "aero"};
  const std::string_view head = core_field.substr(0, core_field.find_first_of(".["));
  for (const std::string_view h : kSceneHeads) {
    if (head == h) return true;
  }
  return false;
}

bool SetError(ApiError* error, ErrorCode code, const std::string& path, const nlohmann::json* value,
              const std::string& rule) {
  if (error->code) return false;
  const int status = ErrorCodeStatus(code);
  std::string message = path.empty() ? "body" : path;
  if (value != nullptr) message += " = " + Show(*value);
  message += value != nullptr ? ": " + rule : " " + rule;
  *error = ApiError{status, code, std::move(message), path};
  return false;
}

ObjectReader::ObjectReader(const nlohmann::json& value, std::string path, ApiError* error)
    : value_(&value), path_(std::move(path)), error_(error) {
  if (!value.is_object()) {
    SetError(error_, ErrorCode::kInvalidValue, path_, &value, "must be an object");
    return;
  }
  members_.reserve(value.size());
  for (const auto& [key, member] : value.get_ref<const nlohmann::json::object_t&>()) {
    members_.push_back({key, &member});
  }
}

const ObjectReader::Member* ObjectReader::Find(std::string_view key) const {
  for (const Member& m : members_) {
    if (m.key == key) return &m;
  }
  return nullptr;
}

const ObjectReader::Member* ObjectReader::Mark(std::string_view key) {
  asked_.insert(asked_.end(), key.begin(), key.end());
  asked_.push_back('\0');
  const Member* m = Find(key);
  if (m != nullptr) members_[static_cast<std::size_t>(m - members_.data())].asked = true;
  return m;
}

std::vector<std::string> ObjectReader::AskedNames() const {
  std::vector<std::string> names;
  const std::string_view asked(asked_.data(), asked_.size());
  for (std::size_t at = 0; at < asked.size();) {
    const std::size_t end = asked.find('\0', at);
    names.emplace_back(asked.substr(at, end - at));
    at = end + 1;
  }
  std::sort(names.begin(), names.end());
  names.erase(std::unique(names.begin(), names.end()), names.end());
  return names;
}

bool ObjectReader::HasTradeSpelling() const {
  // Once per object (SiFormsOf allocates nothing for a key that is no trade spelling): a plain
  // request's every absent field would otherwise build its TradeForms and look them up.
  if (has_trade_spelling_ < 0) {
    has_trade_spelling_ = 0;
    for (const Member& m : members_) {
      if (!SiFormsOf(m.key).empty()) {
        has_trade_spelling_ = 1;
        break;
      }
    }
  }
  return has_trade_spelling_ == 1;
}

bool ObjectReader::Has(std::string_view key) { return Get(key) != nullptr; }

const nlohmann::json* ObjectReader::Get(std::string_view key) {
  if (!value_->is_object()) return nullptr;
  const Member* m = Mark(key);
  return m != nullptr ? m->value : nullptr;
}

bool ObjectReader::Fail(std::string_view key, const std::string& rule, ErrorCode code) {
  const Member* m = Find(key);
  return SetError(error_, code, PathOf(key), m != nullptr ? m->value : nullptr, rule);
}

bool ObjectReader::Missing(std::string_view key) {
  // A required field that is absent, beside a field this object does not know that is one
  // typo away from it or from one of its trade forms ("lenght_in" for length_m): the field
  // as the user wrote it is the error, with the name meant.
  if (value_->is_object()) {
    std::vector<std::string> names = {std::string(key)};
    for (const TradeForm& form : TradeForms(key)) names.push_back(form.key);
    for (const Member& m : members_) {
      if (m.asked) continue;
      const std::string nearest = NearestName(m.key, names);
      if (nearest.empty()) continue;
      Mark(key);
      return SetError(error_, ErrorCode::kUnknownField, PathOf(m.key), nullptr,
                      "is not a known field; did you mean " + nearest + "?");
    }
  }
  return SetError(error_, ErrorCode::kMissingField, PathOf(key), nullptr, "is required");
}

const nlohmann::json* ObjectReader::GetInUnits(std::string_view key, std::string_view* given_as,
                                               double* to_si) {
  *given_as = key;
  *to_si = 1.0;
  const nlohmann::json* found = Get(key);
  if (!value_->is_object() || !HasTradeSpelling()) return found;
  for (const TradeForm& form : TradeForms(key)) {
    if (Find(form.key) == nullptr) continue;
    const Member* member = Mark(form.key);
    if (found != nullptr) {
      // Exactly one form per quantity: two could disagree.
      Fail(form.key, "cannot be given together with " + PathOf(*given_as) +
                         " (one quantity, give it in one form)");
      return nullptr;
    }
    found = member->value;
    *given_as = member->key;  // the object's own string (form.key is a temporary's)
    *to_si = form.to_si;
  }
  return found;
}

bool ObjectReader::HasInUnits(std::string_view key) const {
  if (!value_->is_object()) return false;
  if (Find(key) != nullptr) return true;
  if (!HasTradeSpelling()) return false;
  for (const TradeForm& form : TradeForms(key)) {
    if (Find(form.key) != nullptr) return true;
  }
  return false;
}

bool ObjectReader::Number(std::string_view key, const NumberRule& rule, double* out) {
  if (!ok()) return false;
  if (!HasInUnits(key)) return Missing(key);
  return OptionalNumber(key, rule, out);
}

bool ObjectReader::OptionalNumber(std::string_view key, const NumberRule& rule, double* out) {
  if (!ok()) return false;
  std::string_view given_as;
  double to_si = 1.0;
  const nlohmann::json* value = GetInUnits(key, &given_as, &to_si);
  if (!ok()) return false;
  if (value == nullptr) return true;
  if (!value->is_number()) {
    return Fail(given_as, rule.integer ? "must be an integer" : "must be a number");
  }
  const double number = value->get<double>() * to_si;
  if (!rule.Accepts(number)) {
    // The rule is the SI field's: say what the value is in it.
    return Fail(given_as, given_as == key
                              ? DescribeRefusal(rule, number)
                              : DescribeRefusal(rule, number) + " as " + std::string(key) + " (" +
                                    core::FormatNumber(number) + ")");
  }
  *out = number;
  return true;
}

std::optional<double> ObjectReader::MaybeNumber(std::string_view key, const NumberRule& rule) {
  double value = 0.0;
  if (!ok()) return std::nullopt;
  if (!HasInUnits(key)) {
    Skip(key);
    return std::nullopt;
  }
  if (!OptionalNumber(key, rule, &value)) return std::nullopt;
  return value;
}

bool ObjectReader::OptionalInteger(std::string_view key, long long min, long long max,
                                   long long* out) {
  if (!ok()) return false;
  const nlohmann::json* value = Get(key);
  if (value == nullptr) return true;
  const NumberRule rule = IntegerBetween(static_cast<double>(min), static_cast<double>(max));
  // 2.0 is accepted as 2; 2.7 and -1 for an unsigned field are refused (pitfalls.md).
  if (!value->is_number()) return Fail(key, "must be an integer");
  // An integer literal is compared exactly: through a double, 2^53 + 1 would pass a maximum
  // of 2^53 and be read as 2^53.
  if (value->is_number_unsigned()) {
    const auto number = value->get<unsigned long long>();
    if (max < 0 || number > static_cast<unsigned long long>(max) ||
        (min > 0 && number < static_cast<unsigned long long>(min))) {
      return Fail(key, rule.Describe());
    }
    *out = static_cast<long long>(number);
    return true;
  }
  if (value->is_number_integer()) {
    const auto number = value->get<long long>();
    if (number < min || number > max) return Fail(key, rule.Describe());
    *out = number;
    return true;
  }
  const double number = value->get<double>();
  if (!rule.Accepts(number)) return Fail(key, DescribeRefusal(rule, number));
  *out = static_cast<long long>(number);
  return true;
}

bool ObjectReader::OptionalInt(std::string_view key, int* out) {
  long long value = *out;
  if (!OptionalInteger(key, std::numeric_limits<int>::min(), std::numeric_limits<int>::max(),
                       &value)) {
    return false;
  }
  *out = static_cast<int>(value);
  return true;
}

bool ObjectReader::String(std::string_view key, std::string* out,
                          const std::vector<std::string>& allowed) {
  if (!ok()) return false;
  if (!Has(key)) return Missing(key);
  return OptionalString(key, out, allowed);
}

bool ObjectReader::OptionalString(std::string_view key, std::string* out,
                                  const std::vector<std::string>& allowed) {
  if (!ok()) return false;
  const nlohmann::json* value = Get(key);
  if (value == nullptr) return true;
  if (!value->is_string()) return Fail(key, "must be a string");
  const std::string text = value->get<std::string>();
  if (!allowed.empty()) {
    bool found = false;
    std::string list;
    for (const auto& a : allowed) {
      found = found || a == text;
      list += (list.empty() ? "" : ", ") + a;
    }
    if (!found) return Fail(key, "must be one of " + list);
  }
  *out = text;
  return true;
}

bool ObjectReader::OptionalBool(std::string_view key, bool* out) {
  if (!ok()) return false;
  const nlohmann::json* value = Get(key);
  if (value == nullptr) return true;
  if (!value->is_boolean()) return Fail(key, "must be true or false");
  *out = value->get<bool>();
  return true;
}

bool ObjectReader::Finish() {
  if (!ok() || !value_->is_object()) return ok();
  for (const Member& m : members_) {
    if (!m.asked) {
      const std::vector<std::string> known = AskedNames();
      std::string list;
      for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
      const std::string nearest = NearestName(m.key, known);
      return SetError(error_, ErrorCode::kUnknownField, PathOf(m.key), nullptr,
                      "is not a known field" +
                          (nearest.empty() ? std::string() : "; did you mean " + nearest + "?") +
                          (list.empty() ? std::string(" (this object takes no fields)")
                                        : " (known: " + list + ")"));
    }
  }
  return true;
}

}  // namespace sweetspot::api
