// sweetspot: the command-line tool. Runs the same handlers as the HTTP
// service without a network: `sweetspot PATH [FILE|-]` prints the response
// body to stdout and exits 0 for a 2xx answer, 2 for a 4xx answer, 1 otherwise.
// `sweetspot explore --shard I/N FILE` runs shard I of N of a sweep (NDJSON);
// `sweetspot explore-merge FILE...` merges the shards' outputs into the sweep's.
// A sweep's rows (ndjson, csv) are written to stdout as they are evaluated.
#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <iterator>
#include <limits>
#include <memory>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "api/json_reader.hpp"
#include "api/memory_reserve.hpp"
#include "api/router.hpp"
#include "server/cli_merge.hpp"
#include "server/cli_progress.hpp"
#include "server/cpu_quota.hpp"
#include "server/run.hpp"

namespace {

std::string Usage() {
  std::ostringstream text;
  text << "Usage: sweetspot [-X METHOD] [--max-batch-samples N|none] [--explore-threads N]\n"
       << "                 PATH [FILE|-]\n"
       << "       sweetspot explore --shard I/N [FILE|-]\n"
       << "       sweetspot explore-merge [--progress=MODE] FILE...\n"
       << "       sweetspot threads   (the default thread count and what it comes from)\n"
       << "       sweetspot serve [SERVER OPTIONS]   (as sweetspot-server; see its --help)\n"
       << "  PATH  an endpoint path without the leading /v1/ (e.g. bat/properties);\n"
       << "        health, openapi.json and metrics name the top-level paths\n"
       << "  FILE  the JSON request body of a POST endpoint; - or no FILE reads\n"
       << "        standard input. GET endpoints take no body.\n"
       << "  -X    the method when a path has several (default: POST if the path\n"
       << "        has one, else GET)\n"
       << "  --max-batch-samples N|none  explore only: the most designs a sweep may have\n"
       << "        (also SWEETSPOT_MAX_BATCH_SAMPLES; default none: no limit, the rows are\n"
       << "        streamed to stdout)\n"
       << "  --explore-threads N  explore only: threads to evaluate the designs on, 1 to\n"
       << "        1024 (also SWEETSPOT_EXPLORE_THREADS; default: the CPUs this process may\n"
       << "        use: its affinity mask and its cgroup's cpu.max quota); the rows and\n"
       << "        their order are the same whatever N\n"
       << "  --shard I/N  explore only: run shard I (0-based) of N of the sweep, as\n"
       << "        NDJSON (or CSV when the request's format is csv); design i is in\n"
       << "        shard i mod N\n"
       << "  --progress=auto|on|off|lines  explore, explore-merge, optimize, compare: a bar\n"
       << "        with the rate and the time left on stderr (auto: only when stderr is a\n"
       << "        terminal; lines: one plain line every 5 s, for batch logs); stdout is\n"
       << "        the same bytes whatever the mode\n"
       << "  explore-merge  reads the outputs of all N shards of one sweep (all NDJSON or\n"
       << "        all CSV) as streams and prints the sweep's output: rows in index order\n"
       << "        (NDJSON: then the summary of the whole sweep, Pareto front over all\n"
       << "        rows), the unsharded sweep's bytes but timing_s; refuses shards of\n"
       << "        different sweeps, missing (named) or repeated shards, unfinished shards\n"
       << "Prints the response body; exit status 0 for a 2xx answer, 2 for 4xx,\n"
       << "1 otherwise.\n\nPaths:\n";
  for (const auto& route : sweetspot::api::Routes()) {
    std::string path = route.path;
    if (path.rfind("/v1/", 0) == 0) {
      path = path.substr(4);
    } else if (!path.empty() && path.front() == '/') {
      path = path.substr(1);
    }
    text << "  " << route.method << " " << path << "\n      " << route.summary << "\n";
  }
  return text.str();
}

bool ReadFile(const std::string& file, std::string* text) {
  if (file == "-") {
    text->assign(std::istreambuf_iterator<char>(std::cin), std::istreambuf_iterator<char>());
    return true;
  }
  std::ifstream in(file, std::ios::binary);
  if (!in) return false;
  text->assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  return true;
}

// Takes "--progress=MODE" or "--progress MODE" out of `args` into *options: false (and the
// reason on stderr) for a mode that is not auto, on, off or lines.
bool TakeProgressFlag(std::vector<std::string>* args,
                      sweetspot::server::ProgressOptions* options) {
  for (std::size_t i = 0; i < args->size(); ++i) {
    std::string value;
    std::size_t taken = 1;
    if ((*args)[i].rfind("--progress=", 0) == 0) {
      value = (*args)[i].substr(11);
    } else if ((*args)[i] == "--progress" && i + 1 < args->size()) {
      value = (*args)[i + 1];
      taken = 2;
    } else {
      continue;
    }
    if (!sweetspot::server::ParseProgressMode(value, &options->mode)) {
      std::cerr << "sweetspot: --progress \"" << value << "\": must be auto, on, off or lines\n";
      return false;
    }
    args->erase(args->begin() + static_cast<std::ptrdiff_t>(i),
                args->begin() + static_cast<std::ptrdiff_t>(i + taken));
    --i;
  }
  return true;
}

// "I/N" with 0 <= I < N.
bool ParseShard(const std::string& text, unsigned long long* index, unsigned long long* count) {
  const auto slash = text.find('/');
  if (slash == std::string::npos || slash == 0 || slash + 1 == text.size()) return false;
  try {
    std::size_t used = 0;
    *index = std::stoull(text.substr(0, slash), &used);
    if (used != slash) return false;
    *count = std::stoull(text.substr(slash + 1), &used);
    if (used != text.size() - slash - 1) return false;
  } catch (const std::exception&) {
    return false;
  }
  return text[0] != '-' && *count >= 1 && *index < *count;
}

// "N" (1 to 10^15) or "none" (no limit).
bool ParseBatchLimit(const std::string& text, std::size_t* limit) {
  if (text == "none") {
    *limit = std::numeric_limits<std::size_t>::max();
    return true;
  }
  if (text.empty() || text.find_first_not_of("0123456789") != std::string::npos ||
      text.size() > 16) {
    return false;
  }
  const unsigned long long n = std::stoull(text);
  if (n < 1 || n > 1000000000000000ULL) return false;
  *limit = static_cast<std::size_t>(n);
  return true;
}

// "N" in [1, 1024] into *threads.
bool ParseThreads(const std::string& text, int* threads) {
  if (text.empty() || text.size() > 4 ||
      text.find_first_not_of("0123456789") != std::string::npos) {
    return false;
  }
  const int n = std::stoi(text);
  if (n < 1 || n > 1024) return false;
  *threads = n;
  return true;
}

int ExitCode(int status) {
  if (status >= 200 && status < 300) return 0;
  if (status >= 400 && status < 500) return 2;
  return 1;
}

// `sweetspot threads`: what the default thread count comes from, for an operator checking
// a pod or a job.
int ThreadsCommand() {
  const auto known = [](std::optional<int> n) { return n ? nlohmann::json(*n) : nlohmann::json(); };
  std::cout << nlohmann::json{{"threads", sweetspot::server::DefaultThreadCount()},
                              {"affinity_cpus", known(sweetspot::server::AffinityCpus())},
                              {"cgroup_cpu_quota", known(sweetspot::server::CgroupCpuQuota())},
                              {"hardware_concurrency", std::thread::hardware_concurrency()}}
                   .dump()
            << "\n";
  return 0;
}

// `--shard I/N` into the explore request `*body`: false (the reason on stderr) when it is not
// a shard of an explore request.
bool ShardBody(const std::string& shard, const std::string& full_path,
               const sweetspot::api::ApiLimits& limits, std::string* body) {
  unsigned long long index = 0, count = 0;
  if (full_path != "/v1/explore" || !ParseShard(shard, &index, &count)) {
    std::cerr << "sweetspot: --shard \"" << shard
              << "\": must be I/N with 0 <= I < N, and only for explore\n";
    return false;
  }
  // Parsed with the service's limits (depth first: a deep body must not crash the CLI).
  sweetspot::api::ApiError error;
  std::optional<nlohmann::json> request = sweetspot::api::ParseBody(*body, limits, &error);
  if (!request || !request->is_object()) {
    std::cerr << "sweetspot: --shard needs the request as a JSON object"
              << (error.message.empty() ? "" : ": " + error.message) << "\n";
    return false;
  }
  (*request)["shard"] = {{"index", index}, {"count", count}};
  // NDJSON (with its summary, which the merge checks), or CSV when the request asks for it.
  if (request->value("format", std::string()) != "csv") (*request)["format"] = "ndjson";
  *body = request->dump();
  return true;
}

// Prints the answer on stdout (a stream as its chunks come, counting its lines into
// `*lines`): false when a stream did not finish.
bool PrintResponse(const sweetspot::api::Response& response, std::atomic<std::uint64_t>* lines) {
  if (response.stream) {
    // The same chunks the server sends, written as they come: memory stays bounded.
    const bool finished = response.stream([lines](std::string_view chunk) {
      lines->fetch_add(static_cast<std::uint64_t>(std::count(chunk.begin(), chunk.end(), '\n')),
                       std::memory_order_relaxed);
      std::cout.write(chunk.data(), static_cast<std::streamsize>(chunk.size()));
      return static_cast<bool>(std::cout);
    });
    std::cout.flush();
    return finished;
  }
  if (!response.content_type.empty()) {
    std::cout << response.text;
  } else {
    std::cout << response.body.dump(2, ' ', false, nlohmann::json::error_handler_t::replace)
              << "\n";
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  // As sweetspot-server's main (server/server_main.cpp): a sweep that runs out of memory ends
  // with an error, in `sweetspot serve` and in the CLI's own sweeps.
  sweetspot::api::InstallMemoryReserve(256u << 20);
  std::vector<std::string> args(argv + 1, argv + argc);
  if (!args.empty() && args[0] == "serve") {
    return sweetspot::server::RunServerMain(std::vector<std::string>(args.begin() + 1, args.end()));
  }
  if (!args.empty() && (args[0] == "--help" || args[0] == "-h")) {
    std::cout << Usage();
    return 0;
  }
  if (args.size() == 1 && args[0] == "threads") return ThreadsCommand();
  sweetspot::server::ProgressOptions progress_options;
  if (!TakeProgressFlag(&args, &progress_options)) return 2;
  if (!args.empty() && args[0] == "explore-merge") {
    return sweetspot::server::ExploreMergeCommand(
        std::vector<std::string>(args.begin() + 1, args.end()), progress_options);
  }
  std::string method;
  if (args.size() >= 2 && args[0] == "-X") {
    method = args[1];
    args.erase(args.begin(), args.begin() + 2);
  }
  // The CLI's rows go to stdout as they are evaluated: a sweep has no limit unless told.
  sweetspot::api::Context context;  // default limits; no jobs, no metrics
  context.batch = true;
  context.limits.max_batch_samples = std::numeric_limits<std::size_t>::max();
  std::string batch_limit;
  if (const char* env = std::getenv("SWEETSPOT_MAX_BATCH_SAMPLES")) batch_limit = env;
  std::string shard, explore_threads;
  if (const char* env = std::getenv("SWEETSPOT_EXPLORE_THREADS")) explore_threads = env;
  for (std::size_t i = 0; i < args.size();) {
    if ((args[i] == "--shard" || args[i] == "--max-batch-samples" ||
         args[i] == "--explore-threads") &&
        i + 1 < args.size()) {
      (args[i] == "--shard"             ? shard
       : args[i] == "--explore-threads" ? explore_threads
                                        : batch_limit) = args[i + 1];
      args.erase(args.begin() + static_cast<std::ptrdiff_t>(i),
                 args.begin() + static_cast<std::ptrdiff_t>(i) + 2);
    } else {
      ++i;
    }
  }
  if (!batch_limit.empty() && !ParseBatchLimit(batch_limit, &context.limits.max_batch_samples)) {
    std::cerr << "sweetspot: --max-batch-samples (or SWEETSPOT_MAX_BATCH_SAMPLES) \"" << batch_limit
              << "\": must be an integer in [1, 10^15] or none\n";
    return 2;
  }
  // The CPUs this process may use (cgroup cpu.max, affinity), not the node's cores.
  context.explore_threads = sweetspot::server::DefaultThreadCount();
  if (!explore_threads.empty() && !ParseThreads(explore_threads, &context.explore_threads)) {
    std::cerr << "sweetspot: --explore-threads (or SWEETSPOT_EXPLORE_THREADS) \"" << explore_threads
              << "\": must be an integer in [1, 1024]\n";
    return 2;
  }
  if (args.empty() || args.size() > 2) {
    std::cerr << Usage();
    return 2;
  }
  std::string path = args[0];
  if (!path.empty() && path.front() == '/') path.erase(0, 1);
  if (path.rfind("v1/", 0) == 0) path.erase(0, 3);

  // /v1/PATH first, then /PATH (health, openapi.json, metrics).
  std::string full_path = "/v1/" + path;
  auto routes = sweetspot::api::MatchRoutes(full_path);
  if (routes.empty() && !sweetspot::api::MatchRoutes("/" + path).empty()) {
    full_path = "/" + path;
    routes = sweetspot::api::MatchRoutes(full_path);
  }
  if (method.empty()) {
    method = routes.empty() ? "GET" : routes.front()->method;
    for (const auto* route : routes) {
      if (route->method == "POST") method = "POST";
    }
  }

  std::string body;
  if (method == "POST" || method == "PUT" || method == "PATCH") {
    const std::string file = args.size() == 2 ? args[1] : "-";
    if (!ReadFile(file, &body)) {
      std::cerr << "sweetspot: cannot read " << file << "\n";
      return 1;
    }
  }
  if (!shard.empty() && !ShardBody(shard, full_path, context.limits, &body)) return 2;
  // The long runs report their fraction here (the CLI never cancels them); stderr shows it:
  // a sweep's rows as they are written, the starts of an optimisation, the bats compared.
  sweetspot::core::Progress progress;
  context.progress = &progress;
  std::atomic<std::uint64_t> lines{0};
  std::unique_ptr<sweetspot::server::ProgressReporter> reporter;
  if (full_path == "/v1/explore" || full_path == "/v1/optimize" || full_path == "/v1/compare") {
    reporter = std::make_unique<sweetspot::server::ProgressReporter>(
        path, full_path == "/v1/explore" ? "rows" : "", progress_options, [&progress, &lines] {
          return sweetspot::server::ProgressSample{progress.Fraction(),
                                                   lines.load(std::memory_order_relaxed)};
        });
  }
  const auto response = sweetspot::api::Dispatch({method, full_path, body}, context, nullptr,
                                                 /*allow_stream=*/true);
  if (!response.internal_error.empty()) {
    // What the top-level handler caught: on stderr, never in the printed body.
    std::cerr << nlohmann::json{{"path", full_path},
                                {"status", response.status},
                                {"error", response.internal_error}}
                     .dump(-1, ' ', false, nlohmann::json::error_handler_t::replace)
              << "\n";
  }
  const bool printed = PrintResponse(response, &lines);
  if (reporter) reporter->Finish();
  if (!printed) return 1;
  return ExitCode(response.status);
}
