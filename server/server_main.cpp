// sweetspot-server: the HTTP service in the foreground. Logs to stderr; stops
// cleanly on SIGTERM or SIGINT (in-flight requests are answered first).
#include <unistd.h>

#include <cstdlib>
#include <string>
#include <vector>

#include "api/memory_reserve.hpp"
#include "server/run.hpp"

namespace {

// glibc's malloc keeps 7 freed chunks of each size per thread (tcache) by default; a request
// frees hundreds of small JSON nodes and strings, the rest goes to the arena's fast bins, and
// the next allocation over 1 KiB (the answer's body) consolidates them, on every request. With
// 64 per size the server used about a fifth less CPU per request (bench/cpu_per_request.sh,
// docs/http-bench.md). The cache size is a glibc tunable read at start only: the server sets
// it and executes itself again, once; an operator's own GLIBC_TUNABLES (even empty) is kept.
void UseLargerMallocCache(char** argv) {
  if (std::getenv("GLIBC_TUNABLES") != nullptr) return;
  if (setenv("GLIBC_TUNABLES", "glibc.malloc.tcache_count=64", 1) != 0) return;
  execv("/proc/self/exe", argv);
  unsetenv("GLIBC_TUNABLES");  // not executed again: the defaults
}

}  // namespace

int main(int argc, char** argv) {
  UseLargerMallocCache(argv);
  // 256 MiB of address space kept back for when memory runs out (RLIMIT_AS, or no overcommit):
  // a sweep then stops with an error answer instead of the process ending in std::terminate
  // (api/memory_reserve.hpp). Not 64 MiB: glibc's malloc maps a new 64 MiB heap for a thread's
  // arena when its own is full, so one such heap took a 64 MiB reserve whole and the next
  // thread's allocation failed inside nlohmann-json's destructor (measured under prlimit
  // --as=1500000000). Untouched, it costs no resident memory.
  sweetspot::api::InstallMemoryReserve(256u << 20);
  return sweetspot::server::RunServerMain(std::vector<std::string>(argv + 1, argv + argc));
}
