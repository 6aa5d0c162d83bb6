// sweetspot-server: the HTTP service in the foreground. Logs to stderr; stops
// cleanly on SIGTERM or SIGINT (in-flight requests are answered first).
#include <string>
#include <vector>

#include "server/run.hpp"

int main(int argc, char** argv) {
  return sweetspot::server::RunServerMain(std::vector<std::string>(argv + 1, argv + argc));
}
