#include "tests/hard_cases/hard_case.hpp"

#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <iomanip>
#include <iostream>
#include <thread>
#include <utility>

#include "api/router.hpp"
#include "server/jobs/job_manager.hpp"

namespace sweetspot::hard_cases {
namespace {

using Json = nlohmann::json;

bool TerminationMatches(const std::string& required, const std::string& actual) {
  if (required == "usable") return actual == "converged" || actual == "no_convergence";
  return required == actual;
}

// The job manager of as_job rows: two workers running the router, as the server does.
server::JobManager& Jobs() {
  static server::JobManager manager(server::JobConfig{},
                                 [](const api::Request& inner, core::Progress* progress) {
                                   api::Context context;
                                   context.progress = progress;
                                   return api::Dispatch(inner, context);
                                 });
  return manager;
}

// Waits until job `id` is finished (at most 60 s: only reached if the job hangs). A job must
// not outlive its test: the job manager is a static, and a worker still running at exit
// would use statics (the material catalogue) that exit has already destroyed.
void WaitUntilFinished(const std::string& id, const api::Context& context) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (std::chrono::steady_clock::now() < deadline) {
    const api::Response status = api::Dispatch({"GET", "/v1/jobs/" + id, ""}, context);
    const std::string state = status.body.value("state", "");
    if (state == "done" || state == "failed" || state == "cancelled") return;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  ADD_FAILURE() << "job " << id << " did not finish within 60 s";
}

// Runs `c` as a job: submit, wait until it is finished (at most 60 s: only reached if the job
// hangs), fetch the result.
api::Response RunAsJob(const ApiCase& c) {
  api::Context context;
  context.jobs = &Jobs();
  Json submit{{"path", c.path}, {"body", Json::parse(c.body)}};
  const api::Response queued = api::Dispatch({"POST", "/v1/jobs", submit.dump()}, context);
  // A request its endpoint refuses while parsing is refused at submit with the same answer
  // (no job is made); one refused later (by core) becomes a failed job with that answer.
  if (queued.status != 202) {
    EXPECT_GE(queued.status, 400) << queued.body.dump();
    EXPECT_LT(queued.status, 500) << queued.body.dump();
    return queued;
  }
  const std::string id = queued.body["id"].get<std::string>();
  WaitUntilFinished(id, context);
  return api::Dispatch({"GET", "/v1/jobs/" + id + "/result", ""}, context);
}

void CheckResponse(const ApiCase& c, const api::Response& r, const std::string& how) {
  SCOPED_TRACE(how);
  const std::string dump = r.body.dump().substr(0, 2000);
  // Invariants of every answer.
  EXPECT_NE(r.status, 500) << dump;
  std::string where;
  EXPECT_TRUE(AllFinite(r.body, &where)) << "non-finite number at " << where << ": " << dump;
  EXPECT_TRUE(r.body.is_object()) << dump;
  ASSERT_EQ(r.status, c.status) << dump;
  if (c.status >= 400) {
    EXPECT_EQ(r.body.value("code", ""), c.code) << dump;
    // The field is a string, or null for errors about the body as a whole (c.field empty).
    ASSERT_TRUE(r.body.contains("field")) << dump;
    const Json& field = r.body["field"];
    EXPECT_EQ(field.is_string() ? field.get<std::string>()
              : field.is_null() ? ""
                                : field.dump(),
              c.field)
        << dump;
    EXPECT_FALSE(r.body.value("message", "").empty()) << dump;
    return;
  }
  for (const JsonCheck& check : c.checks) {
    const Json::json_pointer pointer(check.pointer);
    ASSERT_TRUE(r.body.contains(pointer)) << check.pointer << " missing: " << dump;
    const Json& v = r.body.at(pointer);
    if (check.equals.has_value()) {
      EXPECT_EQ(v.is_string() ? v.get<std::string>() : v.dump(), *check.equals) << check.pointer;
      continue;
    }
    ASSERT_TRUE(v.is_number()) << check.pointer << " = " << v.dump();
    const long double x = v.get<double>();
    EXPECT_GE(x, check.lo) << check.pointer << " = " << v.dump();
    EXPECT_LE(x, check.hi) << check.pointer << " = " << v.dump();
  }
}

}  // namespace

Outcome Value(long double value) { return {"converged", "", value}; }

Outcome FromSummary(const core::Summary& summary, long double value) {
  return {core::TerminationName(summary.termination), summary.message, value};
}

Outcome Invalid(std::string why) { return {"invalid_input", std::move(why), kNaN}; }

Expected Expected::With(std::string required) const {
  Expected out = *this;
  out.termination = std::move(required);
  return out;
}

Expected Exactly(long double exact, long double abs_tolerance) {
  Expected e;
  e.kind = Expected::Kind::kValue;
  e.reference = [exact] { return exact; };
  e.abs_tolerance = abs_tolerance;
  return e;
}

Expected Reference(std::function<long double()> reference, long double rel_tolerance,
                   long double abs_tolerance) {
  Expected e;
  e.kind = Expected::Kind::kValue;
  e.reference = std::move(reference);
  e.rel_tolerance = rel_tolerance;
  e.abs_tolerance = abs_tolerance;
  return e;
}

Expected Within(long double lo, long double hi) {
  Expected e;
  e.kind = Expected::Kind::kRange;
  e.lo = lo;
  e.hi = hi;
  return e;
}

Expected Refused(std::string termination, std::string phrase) {
  Expected e;
  e.kind = Expected::Kind::kRefusal;
  e.termination = std::move(termination);
  e.phrase = std::move(phrase);
  return e;
}

void CheckCoreCase(const CoreCase& c) {
  const Outcome out = c.run();
  const Expected& e = c.expected;
  EXPECT_TRUE(TerminationMatches(e.termination, out.termination))
      << "termination " << out.termination << ", expected " << e.termination << ": " << out.message;
  switch (e.kind) {
    case Expected::Kind::kRefusal:
      EXPECT_NE(out.message.find(e.phrase), std::string::npos)
          << "message \"" << out.message << "\" lacks \"" << e.phrase << "\"";
      break;
    case Expected::Kind::kValue: {
      const long double ref = e.reference();
      ASSERT_TRUE(std::isfinite(ref)) << "the reference is not finite";
      ASSERT_TRUE(std::isfinite(out.value))
          << "value " << static_cast<double>(out.value) << ": " << out.message;
      const long double bound = std::max(e.abs_tolerance, e.rel_tolerance * std::fabs(ref));
      const long double error = std::fabs(out.value - ref);
      if (std::getenv("HARD_CASE_VERBOSE") != nullptr) {
        std::cout << std::setprecision(6) << "  [" << c.name << "] error " << error << " (relative "
                  << error / std::fabs(ref) << "), bound " << bound << "\n";
      }
      EXPECT_LE(error, bound) << std::setprecision(20) << "value " << out.value << ", reference "
                              << ref << ", error " << error << " > bound " << bound
                              << " (relative error " << error / std::fabs(ref) << ")";
      break;
    }
    case Expected::Kind::kRange:
      ASSERT_TRUE(std::isfinite(out.value))
          << "value " << static_cast<double>(out.value) << ": " << out.message;
      EXPECT_GE(out.value, e.lo) << std::setprecision(20) << out.value;
      EXPECT_LE(out.value, e.hi) << std::setprecision(20) << out.value;
      break;
  }
}

void PrintTo(const CoreCase& c, std::ostream* os) { *os << c.name; }

JsonCheck Near(std::string pointer, long double expected, long double tolerance) {
  return {std::move(pointer), expected - tolerance, expected + tolerance, std::nullopt};
}

JsonCheck Between(std::string pointer, long double lo, long double hi) {
  return {std::move(pointer), lo, hi, std::nullopt};
}

JsonCheck Is(std::string pointer, std::string text) {
  return {std::move(pointer), 0, 0, std::move(text)};
}

ApiCase Ok(std::string name, std::string path, std::string body, std::vector<JsonCheck> checks) {
  ApiCase c;
  c.name = std::move(name);
  c.path = std::move(path);
  c.body = std::move(body);
  c.status = 200;
  c.checks = std::move(checks);
  return c;
}

ApiCase Refusal(std::string name, std::string path, std::string body, int status, std::string code,
                std::string field) {
  ApiCase c;
  c.name = std::move(name);
  c.path = std::move(path);
  c.body = std::move(body);
  c.status = status;
  c.code = std::move(code);
  c.field = std::move(field);
  return c;
}

ApiCase AsJob(ApiCase c) {
  c.as_job = true;
  return c;
}

void CheckApiCase(const ApiCase& c) {
  // Job submissions need the job manager; everything else runs as the CLI would.
  api::Context context;
  if (c.path.rfind("/v1/jobs", 0) == 0) context.jobs = &Jobs();
  const api::Response direct = api::Dispatch({"POST", c.path, c.body}, context);
  if (context.jobs != nullptr && direct.status == 202 && direct.body.contains("id")) {
    WaitUntilFinished(direct.body["id"].get<std::string>(), context);
  }
  CheckResponse(c, direct, "direct");
  if (c.as_job) CheckResponse(c, RunAsJob(c), "as a job");
}

void PrintTo(const ApiCase& c, std::ostream* os) { *os << c.name; }

std::string SafeName(const std::string& name) {
  std::string out;
  for (const char ch : name) {
    if (ch == '-') {
      out += "Minus";
    } else if (ch == '.') {
      out += 'p';
    } else if (std::isalnum(static_cast<unsigned char>(ch)) || ch == '_') {
      out += ch;
    } else {
      out += '_';
    }
  }
  return out;
}

bool AllFinite(const Json& json, std::string* where) {
  if (json.is_number_float()) {
    if (std::isfinite(json.get<double>())) return true;
    *where = "";
    return false;
  }
  if (json.is_object()) {
    for (const auto& [key, value] : json.items()) {
      if (!AllFinite(value, where)) {
        *where = "/" + key + *where;
        return false;
      }
    }
  } else if (json.is_array()) {
    for (std::size_t i = 0; i < json.size(); ++i) {
      if (!AllFinite(json[i], where)) {
        *where = "/" + std::to_string(i) + *where;
        return false;
      }
    }
  }
  return true;
}

}  // namespace sweetspot::hard_cases
