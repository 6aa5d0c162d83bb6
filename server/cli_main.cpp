// sweetspot: the command-line tool. Runs the same handlers as the HTTP
// service without a network: `sweetspot PATH [FILE|-]` prints the response
// body to stdout and exits 0 for a 2xx answer, 2 for a 4xx answer, 1 otherwise.
#include <fstream>
#include <iostream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include "api/router.hpp"
#include "server/run.hpp"

namespace {

std::string Usage() {
  std::ostringstream text;
  text << "Usage: sweetspot [-X METHOD] PATH [FILE|-]\n"
       << "       sweetspot serve [SERVER OPTIONS]   (as sweetspot-server; see its --help)\n"
       << "  PATH  an endpoint path without the leading /v1/ (e.g. bat/properties);\n"
       << "        health, openapi.json and metrics name the top-level paths\n"
       << "  FILE  the JSON request body of a POST endpoint; - or no FILE reads\n"
       << "        standard input. GET endpoints take no body.\n"
       << "  -X    the method when a path has several (default: POST if the path\n"
       << "        has one, else GET)\n"
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

int ExitCode(int status) {
  if (status >= 200 && status < 300) return 0;
  if (status >= 400 && status < 500) return 2;
  return 1;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  if (!args.empty() && args[0] == "serve") {
    return sweetspot::server::RunServerMain(std::vector<std::string>(args.begin() + 1, args.end()));
  }
  if (!args.empty() && (args[0] == "--help" || args[0] == "-h")) {
    std::cout << Usage();
    return 0;
  }
  std::string method;
  if (args.size() >= 2 && args[0] == "-X") {
    method = args[1];
    args.erase(args.begin(), args.begin() + 2);
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
    if (file == "-") {
      body.assign(std::istreambuf_iterator<char>(std::cin), std::istreambuf_iterator<char>());
    } else {
      std::ifstream in(file, std::ios::binary);
      if (!in) {
        std::cerr << "sweetspot: cannot read " << file << "\n";
        return 1;
      }
      body.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    }
  }
  const sweetspot::api::Context context;  // default limits; no jobs, no metrics
  const auto response = sweetspot::api::Dispatch({method, full_path, body}, context);
  if (!response.content_type.empty()) {
    std::cout << response.text;
  } else {
    std::cout << response.body.dump(2, ' ', false, nlohmann::json::error_handler_t::replace)
              << "\n";
  }
  return ExitCode(response.status);
}
