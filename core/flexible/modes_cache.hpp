// A bounded, thread-safe LRU cache of bat modes, owned by the caller (core keeps no mutable
// globals): the API layer holds one per server and passes a pointer in the options; a null
// pointer means "no cache across requests". Keys are exact: the bit patterns of every number
// that changes the modes (knots, the materials' density / E / G / nu, wall, fill, the theory
// and the accuracy options), never a lossy hash, so two bats share an entry only when their
// modes are identical. Values are immutable (shared_ptr<const BatModes>) and safe to read
// from many threads.
#pragma once

#include <cstddef>
#include <list>
#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>

#include "core/bat/bat.hpp"
#include "core/flexible/modes.hpp"

namespace sweetspot::core {

/// Counters of a ModesCache (monotone since construction).
struct ModesCacheStats {
  long long hits = 0;        ///< Lookups that found an entry.
  long long misses = 0;      ///< Lookups that did not.
  long long evictions = 0;   ///< Entries dropped to respect the capacity.
  std::size_t size = 0;      ///< Entries held now.
  std::size_t capacity = 0;  ///< Largest number of entries held.
};

/// The LRU cache. Thread-safe; no method throws except on allocation failure (callers in core
/// catch that).
class ModesCache {
 public:
  /// Default capacity: 256 entries (a 4-mode entry on a 36-element mesh is ~15 kB, a 12-mode
  /// one ~60 kB: at most ~15 MB).
  static constexpr std::size_t kDefaultCapacity = 256;

  /// A cache holding at most `capacity` entries (0 = caches nothing).
  explicit ModesCache(std::size_t capacity = kDefaultCapacity);
  ModesCache(const ModesCache&) = delete;
  ModesCache& operator=(const ModesCache&) = delete;

  /// The exact key of (bat, options): a byte string of every relevant number's bit pattern.
  static std::string Key(const Bat& bat, const BeamModesOptions& options);

  /// The entry for `key` (and marks it most recently used), or null.
  std::shared_ptr<const BatModes> Find(const std::string& key);
  /// Stores `modes` under `key` (replacing an entry with that key), evicting the least
  /// recently used entries beyond the capacity.
  void Insert(const std::string& key, std::shared_ptr<const BatModes> modes);
  /// Drops every entry (counters kept).
  void Clear();
  /// The counters.
  ModesCacheStats Stats() const;

 private:
  using Entry = std::pair<std::string, std::shared_ptr<const BatModes>>;
  mutable std::mutex mutex_;
  std::size_t capacity_;
  std::list<Entry> order_;  // most recently used first
  std::unordered_map<std::string, std::list<Entry>::iterator> index_;
  long long hits_ = 0;
  long long misses_ = 0;
  long long evictions_ = 0;
};

/// The modes of `bat`: from `cache` when it holds them (and *cache_hit = true), else computed
/// by ComputeBatModes and, when usable, stored. `cache` may be null. Never throws.
std::shared_ptr<const BatModes> CachedBatModes(const Bat& bat, const BeamModesOptions& options,
                                               ModesCache* cache, bool* cache_hit = nullptr);

}  // namespace sweetspot::core
