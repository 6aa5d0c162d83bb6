// The request limits' and the job pool's option tables (server/config_options.hpp).
#include <cmath>
#include <cstdlib>

#include "core/geometry_format.hpp"
#include "server/config_options.hpp"

namespace sweetspot::server::config_options {

// Request limits: bodies, JSON, arrays, samples, answers, solvers.
const std::vector<Option>& LimitOptions() {
  static const std::vector<Option> options = {
      {"--max-json-depth", "SWEETSPOT_MAX_JSON_DEPTH",
       "deepest JSON nesting in a body (default 32)", true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         long long n = 0;
         if (!ParseLong(v, 2, 512, &n, rule)) return false;
         c->limits.max_json_depth = static_cast<int>(n);
         return true;
       }},
      {"--max-array-length", "SWEETSPOT_MAX_ARRAY_LENGTH",
       "longest array anywhere in a body (default 4096)", true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         return SetSize(&c->limits.max_array_length, v, rule);
       }},
      {"--max-string-length", "SWEETSPOT_MAX_STRING_LENGTH",
       "longest string value or key in a body, bytes (default 256)", true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         return SetSize(&c->limits.max_string_length, v, rule);
       }},
      {"--max-knots", "SWEETSPOT_MAX_KNOTS", "knots of a profile (default 256)", true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         return SetSize(&c->limits.max_knots, v, rule);
       }},
      {"--max-variants", "SWEETSPOT_MAX_VARIANTS", "variants in /v1/compare (default 64)", true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         return SetSize(&c->limits.max_variants, v, rule);
       }},
      {"--max-launches", "SWEETSPOT_MAX_LAUNCHES", "launches in one /v1/flight request (default 4096)",
       true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         return SetSize(&c->limits.max_launches, v, rule);
       }},
      {"--max-frontier-values", "SWEETSPOT_MAX_FRONTIER_VALUES",
       "values of one /v1/optimize frontier (default 1000)", true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         return SetSize(&c->limits.max_frontier_values, v, rule);
       }},
      {"--max-jobs-page", "SWEETSPOT_MAX_JOBS_PAGE",
       "jobs on one page of GET /v1/jobs: the largest `limit` (default 1000)", true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         return SetSize(&c->limits.max_jobs_page, v, rule);
       }},
      {"--max-curve-samples", "SWEETSPOT_MAX_CURVE_SAMPLES",
       "points of an exit-speed curve (default 10000)", true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         return SetSize(&c->limits.max_curve_samples, v, rule);
       }},
      {"--max-samples", "SWEETSPOT_MAX_SAMPLES",
       "designs in one /v1/explore request (default 100000)", true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         return SetSize(&c->limits.max_samples, v, rule);
       }},
      {"--max-batch-samples", "SWEETSPOT_MAX_BATCH_SAMPLES",
       "designs in one /v1/explore run as a job, whose rows go to its result (default "
       "1000000; synchronous requests keep --max-samples)",
       true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         return SetSize(&c->limits.max_batch_samples, v, rule);
       }},
      {"--max-response-bytes", "SWEETSPOT_MAX_RESPONSE_BYTES",
       "estimated bytes of an answer built in memory (a synchronous /v1/explore in JSON: rows "
       "x bytes per row); beyond it 413 before the first design (default 67108864)",
       true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         long long n = 0;
         if (!ParseLong(v, 1024, 1LL << 40, &n, rule)) return false;
         c->limits.max_response_bytes = static_cast<std::size_t>(n);
         return true;
       }},
      {"--max-job-cpu-s", "SWEETSPOT_MAX_JOB_CPU_S",
       "a job's estimated CPU time (designs x its models' cost per design), s; beyond it "
       "POST /v1/jobs answers 413 (default 3600)",
       true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         return ParseSecondsUpTo(v, 1e7, &c->limits.max_job_cpu_s, rule);
       }},
      {"--max-design-variables", "SWEETSPOT_MAX_DESIGN_VARIABLES",
       "variables of one /v1/optimize design (default 1000, the optimiser's ceiling)", true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         return SetSize(&c->limits.max_design_variables, v, rule);
       }},
      {"--max-iterations", "SWEETSPOT_MAX_ITERATIONS",
       "solver iterations a request may ask for (default 10000)", true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         long long n = 0;
         if (!ParseLong(v, 1, 100000000, &n, rule)) return false;
         c->limits.max_iterations = static_cast<int>(n);
         return true;
       }},
      {"--max-integration-steps", "SWEETSPOT_MAX_INTEGRATION_STEPS",
       "ODE steps one impact may take (hertz, flexible; default 10000000)", true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         return ParseLong(v, 10, 1000000000, &c->limits.max_integration_steps, rule);
       }},
      {"--max-time-s", "SWEETSPOT_MAX_TIME_S",
       "solver wall time a request may ask for, s (default 60)", true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         return ParseSeconds(v, &c->limits.max_time_s, rule);
       }},
  };
  return options;
}

// The job pool and where jobs are kept.
const std::vector<Option>& JobOptions() {
  static const std::vector<Option> options = {
      {"--job-workers", "SWEETSPOT_JOB_WORKERS", "threads running jobs (default 2)", true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         long long n = 0;
         if (!ParseLong(v, 1, 64, &n, rule)) return false;
         c->jobs.workers = static_cast<int>(n);
         return true;
       }},
      {"--job-queue", "SWEETSPOT_JOB_QUEUE", "queued jobs before 429 (default 64)", true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         return SetSize(&c->jobs.max_queued, v, rule);
       }},
      {"--jobs-kept", "SWEETSPOT_JOBS_KEPT", "finished jobs kept (default 1000)", true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         return SetSize(&c->jobs.max_kept, v, rule);
       }},
      {"--job-keep-s", "SWEETSPOT_JOB_KEEP_S",
       "how long a finished job's result is kept, s (default 3600)", true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         return ParseSeconds(v, &c->jobs.keep_results_s, rule);
       }},
      {"--job-max-resumes", "SWEETSPOT_JOB_MAX_RESUMES",
       "times a job the server died under (crash, SIGKILL) is run again (at start-up, or with "
       "PostgreSQL by another replica once its lease expires) before it is marked failed "
       "(default 2)",
       true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         long long n = 0;
         if (!ParseLong(v, 0, 100, &n, rule)) return false;
         c->jobs.max_resumes = static_cast<int>(n);
         return true;
       }},
      {"--job-lease-s", "SWEETSPOT_JOB_LEASE_S",
       "PostgreSQL: how long a running job's claim lasts unrenewed before another replica "
       "may run it, s (default 10)",
       true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         double s = 0;
         if (!ParseSeconds(v, &s, rule)) return false;
         if (s < 1 || s > 3600) {
           *rule = "must be in [1, 3600] s";
           return false;
         }
         c->jobs.lease_s = s;
         return true;
       }},
      {"--job-max-result-bytes", "SWEETSPOT_JOB_MAX_RESULT_BYTES",
       "the largest job result kept (any jobs database); a larger one fails the job (413 "
       "TooBig) with its size, never truncated (default 268435456)",
       true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         long long n = 0;
         if (!ParseLong(v, 1024, 1000000000000LL, &n, rule)) return false;
         c->jobs.max_result_bytes = static_cast<std::size_t>(n);
         return true;
       }},
      {"--job-results-memory-bytes", "SWEETSPOT_JOB_RESULTS_MEMORY_BYTES",
       "finished jobs' results held in memory in total, bytes: with a SQLite jobs database, "
       "results over 65536 bytes stay in the database only and the oldest small ones leave "
       "memory beyond this; with --jobs-db none, the oldest finished jobs are dropped beyond "
       "it and a larger result fails its job (default 268435456)",
       true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         long long n = 0;
         if (!ParseLong(v, 1024, 1000000000000LL, &n, rule)) return false;
         c->jobs.max_results_memory_bytes = static_cast<std::size_t>(n);
         return true;
       }},
      {"--job-max-time-s", "SWEETSPOT_JOB_MAX_TIME_S",
       "the longest a job may run, s; then it is stopped and failed (408 Timeout) "
       "(default 600)",
       true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         char* end = nullptr;
         const double value = std::strtod(v.c_str(), &end);
         if (v.empty() || end == nullptr || *end != '\0' || !std::isfinite(value) || value <= 0 ||
             value > 1e6) {
           *rule = "must be a number of seconds in (0, 1000000]";
           return false;
         }
         c->jobs.max_time_s = value;
         return true;
       }},
      {"--jobs-db-max-bytes", "SWEETSPOT_JOBS_DB_MAX_BYTES",
       "SQLite: the largest the jobs database file may grow, bytes; past it saves fail as on a "
       "full disk (submits answer 503, a job whose result cannot be saved fails); 0 = no limit "
       "but the disk's (default 4294967296)",
       true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         long long n = 0;
         if (!ParseLong(v, 0, 1000000000000000LL, &n, rule)) return false;
         if (n != 0 && n < 65536) {
           *rule = "must be 0 (no limit) or at least 65536";
           return false;
         }
         c->jobs_db_max_bytes = static_cast<std::size_t>(n);
         return true;
       }},
      {"--jobs-db", "SWEETSPOT_JOBS_DB",
       "where jobs and their results are kept: a SQLite file (default sweetspot-jobs.db in "
       "the working directory), a postgresql://user@host:port/db URI shared by every replica "
       "(one store and one queue), or none = memory only",
       true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         if (v.empty()) {
           *rule = "must be a file path, a postgresql:// URI, or none for no persistence";
           return false;
         }
         c->jobs_db = v;
         return true;
       }},
  };
  return options;
}

}  // namespace sweetspot::server::config_options
