// Design-of-experiments samples over a box of parameters: full grids, Latin
// hypercube and Sobol sequences (Boost.Random's sobol), deterministic shards,
// and the Pareto front of a set of designs. Used by /v1/explore.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/refusal.hpp"

namespace sweetspot::core {

/// One swept parameter: the interval [min, max] and, for grids, its count.
struct SweepDimension {
  double min = 0.0;  ///< Lower end (parameter's unit).
  double max = 0.0;  ///< Upper end (>= min).
  int count = 1;     ///< Grid points (>= 1; 1 = min only); ignored by LHS and Sobol.
};

/// How designs are drawn.
enum class SamplingMethod {
  kGrid,            ///< Full factorial grid: the product of each dimension's evenly spaced points.
  kLatinHypercube,  ///< n points, one per stratum in every dimension, seeded (std::mt19937_64).
  kSobol,  ///< n points of the Sobol sequence (Boost.Random; it starts after the origin), skipping
           ///< the first `seed`.
};

/// Stable names: "grid", "lhs", "sobol".
const char* SamplingMethodName(SamplingMethod method);
/// The method called `name`, or nullopt.
std::optional<SamplingMethod> ParseSamplingMethod(const std::string& name);

/// A sweep: dimensions, method, sample count and seed.
struct SweepPlan {
  std::vector<SweepDimension> dimensions;         ///< 1 to 32 dimensions.
  SamplingMethod method = SamplingMethod::kGrid;  ///< How to draw designs.
  std::uint64_t samples = 0;  ///< LHS/Sobol: number of designs (>= 1); grid: ignored.
  std::uint64_t seed = 0;  ///< LHS: the generator's seed; Sobol: points skipped after the origin.

  /// True when well formed; otherwise the refusal in *refusal (if
  /// non-null): field, value and rule, its Message() "field = value: rule".
  bool Validate(Refusal* refusal) const;
  /// Number of designs: the grid's product of counts, or `samples` (saturates at UINT64_MAX).
  std::uint64_t DesignCount() const;
};

/// A subset of a sweep: design i belongs to shard (i mod count). The shards of
/// a sweep partition it, so their union is the whole sweep, design for design.
struct Shard {
  std::uint64_t index = 0;  ///< This shard, in [0, count).
  std::uint64_t count = 1;  ///< Number of shards (>= 1).

  /// True when index < count and count >= 1; otherwise the refusal in *refusal (if
  /// non-null): field, value and rule, its Message() "field = value: rule".
  bool Validate(Refusal* refusal) const;
  /// True when design `i` belongs to this shard.
  bool Contains(std::uint64_t i) const { return i % count == index; }
};

/// The designs of `plan` (each a point in parameter units, one value per
/// dimension), in design-index order. Deterministic: the same plan gives the
/// same designs bit for bit. Precondition: plan.Validate(nullptr).
std::vector<std::vector<double>> GenerateDesigns(const SweepPlan& plan);

/// Design `i` of a grid plan without generating the others (row-major: the
/// last dimension varies fastest). Precondition: i < plan.DesignCount().
std::vector<double> GridDesign(const SweepPlan& plan, std::uint64_t i);
/// GridDesign into *point (resized; its storage reused design after design).
void GridDesignInto(const SweepPlan& plan, std::uint64_t i, std::vector<double>* point);

/// A plan's designs one at a time, in any order (explore's workers take blocks of indices):
/// a grid point by its index, a Sobol point by a jump of the generator to it (memory bounded
/// whatever the sample count), a Latin hypercube point from the table drawn once at
/// construction (n x dimensions doubles, shared by copies: its strata are a permutation of
/// all n designs). Design i equals GenerateDesigns(plan)[i] bit for bit. Copies share the
/// table and each has its own Sobol position, so give each thread its own copy.
/// Precondition: plan.Validate(nullptr).
class DesignSequence {
 public:
  explicit DesignSequence(const SweepPlan& plan);
  DesignSequence(const DesignSequence& other);
  DesignSequence& operator=(const DesignSequence& other);
  DesignSequence(DesignSequence&&) noexcept;
  DesignSequence& operator=(DesignSequence&&) noexcept;
  ~DesignSequence();

  /// Design `i` (< plan.DesignCount()) into *point (resized; its storage reused).
  void DesignInto(std::uint64_t i, std::vector<double>* point);
  /// Design `i` (< plan.DesignCount()), valid until the next call: this object's own vector,
  /// which a grid's design that follows the last one only steps (no copy).
  const std::vector<double>& Design(std::uint64_t i);

 private:
  struct SobolState;  // Boost's generator and the index of the next point it gives
  // Grid: design `i`'s digits and values from its index, and from the last design's by one
  // step when `i` follows it.
  void SeekGrid(std::uint64_t i);
  void StepGrid();
  SweepPlan plan_;
  std::vector<double> point_;  // the last design (Design's)
  // Grid: the last design's digits (dimension k's in [0, count_k), the last dimension's the
  // fastest), whether they are set, and the index of the design after it.
  std::vector<std::uint64_t> grid_digits_;
  bool grid_set_ = false;
  std::uint64_t grid_next_ = 0;
  std::shared_ptr<const std::vector<double>> table_;  // LHS: design i at [i * dims, (i+1) * dims)
  std::unique_ptr<SobolState> sobol_;
};

/// Whether an objective is maximised or minimised.
enum class Sense { kMaximize, kMinimize };

/// The indices (into `points`) of the non-dominated points: no other point is
/// at least as good in every objective and strictly better in one. Each point
/// has one value per objective, with `senses` giving the direction. Points with
/// a non-finite value are never on the front. Returned in increasing order.
std::vector<std::size_t> ParetoFront(const std::vector<std::vector<double>>& points,
                                     const std::vector<Sense>& senses);

}  // namespace sweetspot::core
