#include "api/memory_reserve.hpp"

#include <atomic>
#include <cstdlib>
#include <mutex>
#include <new>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace sweetspot::api {
namespace {

std::mutex reserve_mutex;                // guards reserve and reserve_bytes
void* reserve = nullptr;                 // the reserve (malloc'd), or null when spent
std::size_t reserve_bytes = 0;           // its size; 0 = not installed
std::atomic<bool> memory_low{false};     // spent and not restored
std::atomic<std::uint64_t> failures{0};  // allocations that failed

// Called by operator new when malloc fails: frees the reserve (operator new then tries again);
// with no reserve left it uninstalls itself, so that operator new throws std::bad_alloc.
void GiveBackReserve() {
  failures.fetch_add(1);
  std::lock_guard<std::mutex> lock(reserve_mutex);
  if (reserve != nullptr) {
    std::free(reserve);
    reserve = nullptr;
    memory_low.store(true);
    return;
  }
  memory_low.store(true);
  std::set_new_handler(nullptr);
}

}  // namespace

void InstallMemoryReserve(std::size_t bytes) {
  std::lock_guard<std::mutex> lock(reserve_mutex);
  if (reserve == nullptr) reserve = std::malloc(bytes);
  reserve_bytes = bytes;
  memory_low.store(reserve == nullptr);
  std::set_new_handler(GiveBackReserve);
}

bool MemoryLow() { return memory_low.load(std::memory_order_relaxed); }

std::uint64_t MemoryFailures() { return failures.load(std::memory_order_relaxed); }

bool RestoreMemoryReserve() {
  if (!memory_low.load()) return true;
  std::lock_guard<std::mutex> lock(reserve_mutex);
  if (reserve_bytes == 0) return true;
#if defined(__GLIBC__)
  // The freed rows stay mapped in the arenas' heaps until trimmed: the reserve's address space
  // would not be found otherwise (under RLIMIT_AS).
  if (reserve == nullptr) malloc_trim(0);
#endif
  if (reserve == nullptr) reserve = std::malloc(reserve_bytes);
  if (reserve == nullptr) return false;
  memory_low.store(false);
  std::set_new_handler(GiveBackReserve);
  return true;
}

}  // namespace sweetspot::api
