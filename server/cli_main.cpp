// sweetspot: the command-line tool. Runs the same handlers as the HTTP
// service without a network: `sweetspot PATH [FILE|-]` prints the response
// body to stdout and exits 0 for a 2xx answer, 2 for a 4xx answer, 1 otherwise.
// `sweetspot explore --shard I/N FILE` runs shard I of N of a sweep (NDJSON);
// `sweetspot explore-merge FILE...` merges the shards' outputs into the sweep's.
// A sweep's rows (ndjson, csv) are written to stdout as they are evaluated.
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <iterator>
#include <limits>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "api/explore/shards.hpp"
#include "api/json_reader.hpp"
#include "api/memory_reserve.hpp"
#include "api/router.hpp"
#include "server/run.hpp"

namespace {

std::string Usage() {
  std::ostringstream text;
  text << "Usage: sweetspot [-X METHOD] [--max-batch-samples N|none] [--explore-threads N]\n"
       << "                 PATH [FILE|-]\n"
       << "       sweetspot explore --shard I/N [FILE|-]\n"
       << "       sweetspot explore-merge FILE...\n"
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
       << "        1024 (also SWEETSPOT_EXPLORE_THREADS; default: one per core); the rows\n"
       << "        and their order are the same whatever N\n"
       << "  --shard I/N  explore only: run shard I (0-based) of N of the sweep, as\n"
       << "        NDJSON (the request's shard and format are set); design i is in\n"
       << "        shard i mod N\n"
       << "  explore-merge  reads the NDJSON outputs of all N shards of one sweep and\n"
       << "        prints the sweep's NDJSON: rows in index order, then the summary of\n"
       << "        the whole sweep (Pareto front over all rows); refuses shards of\n"
       << "        different sweeps, missing or repeated shards, unfinished shards\n"
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

// sweetspot explore-merge FILE...: the merged NDJSON on stdout; 2 when the
// shards do not make one complete sweep (the reason on stderr).
int ExploreMerge(const std::vector<std::string>& files) {
  if (files.empty()) {
    std::cerr << "sweetspot explore-merge: give the NDJSON output of every shard of one sweep\n";
    return 2;
  }
  std::vector<sweetspot::api::ShardOutput> shards;
  for (const std::string& file : files) {
    sweetspot::api::ShardOutput shard{file, {}};
    if (!ReadFile(file, &shard.text)) {
      std::cerr << "sweetspot explore-merge: cannot read " << file << "\n";
      return 1;
    }
    shards.push_back(std::move(shard));
  }
  const sweetspot::api::MergedSweep merged = sweetspot::api::MergeExploreShards(shards);
  if (!merged.ok) {
    std::cerr << "sweetspot explore-merge: " << merged.error << "\n";
    return 2;
  }
  std::cout << merged.ndjson;
  return 0;
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
  if (!args.empty() && args[0] == "explore-merge") {
    return ExploreMerge(std::vector<std::string>(args.begin() + 1, args.end()));
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
  const unsigned cores = std::thread::hardware_concurrency();
  context.explore_threads = cores == 0 ? 1 : static_cast<int>(cores);
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
  if (!shard.empty()) {
    unsigned long long index = 0, count = 0;
    if (full_path != "/v1/explore" || !ParseShard(shard, &index, &count)) {
      std::cerr << "sweetspot: --shard \"" << shard
                << "\": must be I/N with 0 <= I < N, and only for explore\n";
      return 2;
    }
    // Parsed with the service's limits (depth first: a deep body must not crash the CLI).
    sweetspot::api::ApiError error;
    std::optional<nlohmann::json> request = sweetspot::api::ParseBody(body, context.limits, &error);
    if (!request || !request->is_object()) {
      std::cerr << "sweetspot: --shard needs the request as a JSON object"
                << (error.message.empty() ? "" : ": " + error.message) << "\n";
      return 2;
    }
    (*request)["shard"] = {{"index", index}, {"count", count}};
    (*request)["format"] = "ndjson";
    body = request->dump();
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
  if (response.stream) {
    // The same chunks the server sends, written as they come: memory stays bounded.
    const bool finished = response.stream([](std::string_view chunk) {
      std::cout.write(chunk.data(), static_cast<std::streamsize>(chunk.size()));
      return static_cast<bool>(std::cout);
    });
    std::cout.flush();
    if (!finished) return 1;
  } else if (!response.content_type.empty()) {
    std::cout << response.text;
  } else {
    std::cout << response.body.dump(2, ' ', false, nlohmann::json::error_handler_t::replace)
              << "\n";
  }
  return ExitCode(response.status);
}
