// sweetspot-server: the HTTP service in the foreground. Logs to stderr; stops
// cleanly on SIGTERM or SIGINT (in-flight requests are answered first).
#include <string>
#include <vector>

#include "api/memory_reserve.hpp"
#include "server/run.hpp"

int main(int argc, char** argv) {
  // 256 MiB of address space kept back for when memory runs out (RLIMIT_AS, or no overcommit):
  // a sweep then stops with an error answer instead of the process ending in std::terminate
  // (api/memory_reserve.hpp). Not 64 MiB: glibc's malloc maps a new 64 MiB heap for a thread's
  // arena when its own is full, so one such heap took a 64 MiB reserve whole and the next
  // thread's allocation failed inside nlohmann-json's destructor (measured under prlimit
  // --as=1500000000). Untouched, it costs no resident memory.
  sweetspot::api::InstallMemoryReserve(256u << 20);
  return sweetspot::server::RunServerMain(std::vector<std::string>(argv + 1, argv + argc));
}
