// modes_cache: implementation; see modes_cache.hpp.
#include "core/flexible/modes_cache.hpp"

#include <cstring>

namespace sweetspot::core {
namespace {

void PutDouble(std::string* key, double v) {
  char bytes[sizeof(double)];
  std::memcpy(bytes, &v, sizeof(double));
  key->append(bytes, sizeof(double));
}

void PutInt(std::string* key, long long v) {
  char bytes[sizeof(long long)];
  std::memcpy(bytes, &v, sizeof(long long));
  key->append(bytes, sizeof(long long));
}

// The numbers of a material that enter the beam (the name and the source do not).
void PutMaterial(std::string* key, const Material& m) {
  PutDouble(key, m.density_kg_m3);
  PutDouble(key, m.youngs_modulus_pa);
  PutDouble(key, m.EffectiveShearModulusPa());
  PutDouble(key, m.poissons_ratio);
}

}  // namespace

ModesCache::ModesCache(std::size_t capacity) : capacity_(capacity) {}

std::string ModesCache::Key(const Bat& bat, const BeamModesOptions& options) {
  std::string key;
  key.reserve(16 * bat.knots.size() + 160);
  key.append("modes:v1:");
  PutInt(&key, static_cast<long long>(bat.knots.size()));
  for (const ProfileKnot& k : bat.knots) {
    PutDouble(&key, k.x_m);
    PutDouble(&key, k.radius_m);
    PutDouble(&key, k.wall_thickness_m);
  }
  PutMaterial(&key, bat.material);
  PutDouble(&key, bat.wall_thickness_m);
  PutInt(&key, bat.fill.has_value() ? 1 : 0);
  if (bat.fill.has_value()) {
    PutMaterial(&key, bat.fill->material);
    PutDouble(&key, bat.fill->diameter_m);
    PutDouble(&key, bat.fill->depth_m);
  }
  for (const std::optional<BatPart>* part : {&bat.end_cap, &bat.knob}) {
    PutInt(&key, part->has_value() ? 1 : 0);
    if (part->has_value()) {
      PutDouble(&key, (*part)->mass_kg);
      PutDouble(&key, (*part)->length_m);
    }
  }
  PutInt(&key, bat.handle.has_value() ? 1 : 0);
  if (bat.handle.has_value()) {
    PutMaterial(&key, bat.handle->material);
    PutInt(&key, bat.handle->wall_thickness_m.has_value() ? 1 : 0);
    PutDouble(&key, bat.handle->WallM(0.0));
    PutDouble(&key, bat.handle->joint_from_knob_m);
  }
  PutInt(&key, static_cast<long long>(options.theory));
  PutInt(&key, options.num_modes);
  PutDouble(&key, options.relative_tolerance);
  PutInt(&key, options.initial_elements);
  PutInt(&key, options.max_elements);
  PutInt(&key, options.rotary_inertia ? 1 : 0);
  return key;
}

std::shared_ptr<const BatModes> ModesCache::Find(const std::string& key) {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = index_.find(key);
  if (it == index_.end()) {
    ++misses_;
    return nullptr;
  }
  ++hits_;
  order_.splice(order_.begin(), order_, it->second);
  return it->second->second;
}

void ModesCache::Insert(const std::string& key, std::shared_ptr<const BatModes> modes) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (capacity_ == 0) return;
  const auto it = index_.find(key);
  if (it != index_.end()) {
    it->second->second = std::move(modes);
    order_.splice(order_.begin(), order_, it->second);
    return;
  }
  order_.emplace_front(key, std::move(modes));
  index_.emplace(key, order_.begin());
  while (order_.size() > capacity_) {
    index_.erase(order_.back().first);
    order_.pop_back();
    ++evictions_;
  }
}

void ModesCache::Clear() {
  std::lock_guard<std::mutex> lock(mutex_);
  order_.clear();
  index_.clear();
}

ModesCacheStats ModesCache::Stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  ModesCacheStats s;
  s.hits = hits_;
  s.misses = misses_;
  s.evictions = evictions_;
  s.size = order_.size();
  s.capacity = capacity_;
  return s;
}

std::shared_ptr<const BatModes> CachedBatModes(const Bat& bat, const BeamModesOptions& options,
                                               ModesCache* cache, bool* cache_hit) {
  if (cache_hit != nullptr) *cache_hit = false;
  try {
    std::string key;
    if (cache != nullptr) {
      key = ModesCache::Key(bat, options);
      if (auto found = cache->Find(key)) {
        if (cache_hit != nullptr) *cache_hit = true;
        return found;
      }
    }
    auto modes = std::make_shared<const BatModes>(ComputeBatModes(bat, options));
    if (cache != nullptr && modes->summary.IsSolutionUsable()) cache->Insert(key, modes);
    return modes;
  } catch (...) {
    auto failed = std::make_shared<BatModes>();
    failed->summary.termination = Termination::kFailure;
    failed->summary.message = InternalErrorMessage();
    return failed;
  }
}

}  // namespace sweetspot::core
