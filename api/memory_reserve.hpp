// A reserve of memory that makes running out of it recoverable. nlohmann-json allocates while it
// destroys a value (json_value::destroy moves the children onto a std::vector), and destructors
// are noexcept: a std::bad_alloc thrown out of the json code, as the last memory goes, unwinds
// through destructors that allocate again and ends the process in std::terminate (issue "Under
// attack, bounded", item 4: a sweep's rows at a 4 GB cap). With the reserve installed, the
// first allocation that fails frees the reserve and succeeds (std::new_handler), and
// MemoryLow() tells long work (RunSweep, between designs) to stop and unwind with memory to do
// it; a later call of RestoreMemoryReserve() takes the reserve again once memory is back.
#pragma once

#include <cstddef>
#include <cstdint>

namespace sweetspot::api {

/// Takes a reserve of `bytes` and installs the std::new_handler that gives it back when an
/// allocation fails. Process-wide: call once at start-up (the server's main).
void InstallMemoryReserve(std::size_t bytes);

/// True after the reserve was spent by a failed allocation and not yet restored. Always false
/// when no reserve is installed.
bool MemoryLow();

/// How many allocations have failed since start-up (each spent the reserve, or found it spent):
/// work that sees it change since it started stops (RunSweep).
std::uint64_t MemoryFailures();

/// Takes the reserve again if it was spent and memory can be had now (never throws; first gives
/// glibc's free heap memory back to the system, malloc_trim); returns !MemoryLow().
bool RestoreMemoryReserve();

}  // namespace sweetspot::api
