#include "server/config.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "core/geometry_format.hpp"
#include "server/config_options.hpp"

namespace sweetspot::server {

namespace config_options {

// Stopping (the drain, the grace), the web root, the access log.
const std::vector<Option>& ProcessOptions() {
  static const std::vector<Option> options = {
      {"--drain-s", "SWEETSPOT_DRAIN_S",
       "on SIGTERM/SIGINT, how long the server keeps accepting and answering while GET /ready "
       "answers 503, so that a load balancer takes it out first, s; then it stops accepting "
       "and --shutdown-grace-s begins (default 0 = stop accepting at once; 5 behind "
       "Kubernetes)",
       true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         return ParseSecondsOrZero(v, &c->drain_s, rule);
       }},
      {"--shutdown-grace-s", "SWEETSPOT_SHUTDOWN_GRACE_S",
       "on SIGTERM, how long running jobs may finish before they are interrupted and kept "
       "for the next start, s (default 8; 0 = interrupt at once)",
       true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         return ParseSecondsOrZero(v, &c->shutdown_grace_s, rule);
       }},
      {"--web-root", "SWEETSPOT_WEB_ROOT",
       "folder of the design explorer's static files, served at / without a token (default: "
       "the folder web next to the executable; a missing folder answers 404 at /)",
       true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         if (v.empty()) {
           *rule = "must be a folder path";
           return false;
         }
         c->web_root = v;
         return true;
       }},
      {"--access-log", "SWEETSPOT_ACCESS_LOG",
       "one JSON line per request on stderr, 1 or 0 (default 1)", true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         return ParseBool(v, &c->access_log, rule);
       }},
  };
  return options;
}

}  // namespace config_options

namespace {

using config_options::Option;

// Every option, area by area (config_options.hpp), in the order --help lists them.
const std::vector<Option>& Options() {
  static const std::vector<Option> options = [] {
    std::vector<Option> all;
    for (const auto* area :
         {&config_options::ServingOptions(), &config_options::ConnectionOptions(),
          &config_options::RequestReadingOptions(),
          &config_options::LimitOptions(), &config_options::JobOptions(),
          &config_options::ProcessOptions()}) {
      all.insert(all.end(), area->begin(), area->end());
    }
    return all;
  }();
  return options;
}

}  // namespace

bool ServerConfig::Validate(core::Refusal* refusal) const {
  using core::IntegerRefusal;
  using core::NumberRefusal;
  auto fail = [refusal](core::Refusal why) { return core::Refuse(refusal, std::move(why)); };
  if (host.empty()) return fail(core::QuotedRefusal("host", "\"\"", "must not be empty"));
  if (port < 0 || port > 65535) return fail(IntegerRefusal("port", port, "must be in [0, 65535]"));
  if (threads < 1 || threads > 1024) {
    return fail(IntegerRefusal("threads", threads, "must be in [1, 1024]"));
  }
  if (compute_threads < 0 || compute_threads > 1024) {
    return fail(IntegerRefusal("compute_threads", compute_threads,
                               "must be in [0, 1024] (0 = one per core)"));
  }
  if (explore_threads < 0 || explore_threads > 1024) {
    return fail(IntegerRefusal("explore_threads", explore_threads,
                               "must be in [0, 1024] (0 = one per core)"));
  }
  if (max_head_bytes < 256) {
    return fail(IntegerRefusal("max_head_bytes", static_cast<long long>(max_head_bytes),
                               "must be at least 256"));
  }
  if (!std::isfinite(body_min_rate_bytes_per_s) || body_min_rate_bytes_per_s < 1) {
    return fail(NumberRefusal("body_min_rate_bytes_per_s", body_min_rate_bytes_per_s,
                              "must be at least 1"));
  }
  if (max_connections < 1) {
    return fail(IntegerRefusal("max_connections", static_cast<long long>(max_connections),
                               "must be at least 1"));
  }
  if (max_connections_per_client < 1) {
    return fail(IntegerRefusal("max_connections_per_client",
                               static_cast<long long>(max_connections_per_client),
                               "must be at least 1"));
  }
  if (!auth_token.empty() && auth_token.size() < 16) {
    return fail(core::TextRefusal("auth_token", "must have at least 16 characters"));
  }
  if (max_body_bytes < 1) return fail(IntegerRefusal("max_body_bytes", 0, "must be at least 1"));
  for (const auto& [name, value] :
       {std::pair{"header_timeout_s", header_timeout_s},
        std::pair{"read_timeout_s", read_timeout_s}, std::pair{"write_timeout_s", write_timeout_s},
        std::pair{"keep_alive_timeout_s", keep_alive_timeout_s},
        std::pair{"first_byte_timeout_s", first_byte_timeout_s},
        std::pair{"max_request_time_s", max_request_time_s}}) {
    if (!std::isfinite(value) || value <= 0 || value > 3600) {
      return fail(NumberRefusal(name, value, "must be in (0, 3600]"));
    }
  }
  if (core::Refusal why; !limits.Validate(&why)) return fail(core::Prefixed("limits.", why));
  if (core::Refusal why; !jobs.Validate(&why)) return fail(core::Prefixed("jobs.", why));
  if (jobs_db.empty()) {
    return fail(core::QuotedRefusal("jobs_db", "\"\"",
                                    "must be a file path, a postgresql:// URI, or \"" +
                                        std::string(kNoJobsDb) + "\" for no persistence"));
  }
  if (jobs_db_max_bytes != 0 &&
      (jobs_db_max_bytes < 65536 || jobs_db_max_bytes > 1000000000000000ULL)) {
    return fail(core::QuotedRefusal("jobs_db_max_bytes", std::to_string(jobs_db_max_bytes),
                                    "must be 0 (no limit) or in [65536, 1e15]"));
  }
  if (!std::isfinite(drain_s) || drain_s < 0 || drain_s > 3600) {
    return fail(NumberRefusal("drain_s", drain_s, "must be in [0, 3600]"));
  }
  if (!std::isfinite(shutdown_grace_s) || shutdown_grace_s < 0 || shutdown_grace_s > 3600) {
    return fail(NumberRefusal("shutdown_grace_s", shutdown_grace_s, "must be in [0, 3600]"));
  }
  if (keep_alive_max_requests < 1) {
    return fail(IntegerRefusal("keep_alive_max_requests",
                               static_cast<long long>(keep_alive_max_requests),
                               "must be at least 1"));
  }
  return true;
}

ParsedCommandLine ParseCommandLine(
    const std::vector<std::string>& args,
    const std::function<std::optional<std::string>(const std::string&)>& getenv) {
  ParsedCommandLine out;
  std::string rule;
  if (auto token = getenv("SWEETSPOT_AUTH_TOKEN")) out.config.auth_token = *token;
  for (const Option& option : Options()) {
    if (auto value = getenv(option.env)) {
      if (!option.set(&out.config, *value, &rule)) {
        out.error = std::string("environment ") + option.env + " = \"" + *value + "\": " + rule;
        return out;
      }
    }
  }
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& arg = args[i];
    if (arg == "--help" || arg == "-h") {
      out.show_help = true;
      continue;
    }
    std::string name = arg;
    std::optional<std::string> value;
    if (const auto eq = arg.find('='); eq != std::string::npos) {
      name = arg.substr(0, eq);
      value = arg.substr(eq + 1);
    }
    if (name == "--no-access-log" && !value) {
      out.config.access_log = false;
      continue;
    }
    const Option* match = nullptr;
    for (const Option& option : Options()) {
      if (name == option.flag) match = &option;
    }
    if (match == nullptr) {
      out.error = "unknown option " + arg + " (see --help)";
      return out;
    }
    if (!value) {
      if (i + 1 >= args.size()) {
        out.error = "option " + name + " needs a value";
        return out;
      }
      value = args[++i];
    }
    if (!match->set(&out.config, *value, &rule)) {
      out.error = "option " + name + " = \"" + *value + "\": " + rule;
      return out;
    }
  }
  // One flag per job limit: the api's check at submit reads the job runner's limits.
  out.config.limits.max_job_time_s = out.config.jobs.max_time_s;
  out.config.limits.max_job_result_bytes = out.config.jobs.max_result_bytes;
  if (core::Refusal why; !out.config.Validate(&why)) out.error = why.Message();
  return out;
}

std::string Usage(const std::string& program) {
  std::ostringstream text;
  text << "Usage: " << program << " [OPTIONS]\n"
       << "Serves the sweetspot HTTP JSON API in the foreground; logs to stderr;\n"
       << "stops cleanly on SIGTERM or SIGINT. Flags override environment variables.\n\n"
       << "Options:\n";
  for (const Option& option : Options()) {
    text << "  " << option.flag << " VALUE\n      " << option.help << "\n      env: " << option.env
         << "\n";
  }
  text << "  --no-access-log\n      same as --access-log 0\n"
       << "  -h, --help\n      this text\n";
  return text.str();
}

}  // namespace sweetspot::server
