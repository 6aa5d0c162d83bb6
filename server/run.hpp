// Runs the HTTP service in the foreground until SIGTERM or SIGINT.
#pragma once

#include <string>
#include <vector>

namespace sweetspot::server {

/// Parses `args` (flags, without the program name) and the environment, binds,
/// serves until SIGTERM/SIGINT, and returns the process exit status (0 after a
/// clean stop, 2 for a bad option, 1 when the address cannot be bound).
int RunServerMain(const std::vector<std::string>& args);

}  // namespace sweetspot::server
