#include "core/explore/sampling.hpp"

#include <boost/random/sobol.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>

#include "core/geometry_format.hpp"
#include "core/refusal.hpp"

namespace sweetspot::core {
namespace {

// A double in [0, 1) from 53 random bits: the same on every platform
// (std::uniform_real_distribution's algorithm is implementation-defined).
double Unit(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

// An integer in [0, n) without modulo bias (rejection sampling).
std::uint64_t Below(std::mt19937_64& rng, std::uint64_t n) {
  const std::uint64_t limit =
      std::numeric_limits<std::uint64_t>::max() - std::numeric_limits<std::uint64_t>::max() % n;
  std::uint64_t draw;
  do {
    draw = rng();
  } while (draw >= limit);
  return draw % n;
}

double Lerp(const SweepDimension& d, double t) { return d.min + (d.max - d.min) * t; }

// The number of grid values of dimension `d` (a count below 1 is taken as 1).
std::uint64_t GridCountOf(const SweepDimension& d) {
  return static_cast<std::uint64_t>(std::max(d.count, 1));
}

// Value j (< c = GridCountOf(d)) of grid dimension `d`.
double GridValueOf(const SweepDimension& d, std::uint64_t c, std::uint64_t j) {
  return c == 1 ? d.min : Lerp(d, static_cast<double>(j) / static_cast<double>(c - 1));
}

}  // namespace

const char* SamplingMethodName(SamplingMethod method) {
  switch (method) {
    case SamplingMethod::kGrid:
      return "grid";
    case SamplingMethod::kLatinHypercube:
      return "lhs";
    case SamplingMethod::kSobol:
      return "sobol";
  }
  return "grid";
}

std::optional<SamplingMethod> ParseSamplingMethod(const std::string& name) {
  for (const auto m :
       {SamplingMethod::kGrid, SamplingMethod::kLatinHypercube, SamplingMethod::kSobol}) {
    if (name == SamplingMethodName(m)) return m;
  }
  return std::nullopt;
}

bool SweepPlan::Validate(Refusal* why) const {
  if (dimensions.empty() || dimensions.size() > 32) {
    return Refuse(why, "dimensions", static_cast<double>(dimensions.size()),
                  "must have 1 to 32 parameters");
  }
  for (std::size_t i = 0; i < dimensions.size(); ++i) {
    const SweepDimension& d = dimensions[i];
    if (!std::isfinite(d.min)) {
      return Refuse(why, IndexedField("dimensions", i, "min"), d.min, "must be finite");
    }
    if (!std::isfinite(d.max) || d.max < d.min) {
      return Refuse(why, IndexedField("dimensions", i, "max"), d.max,
                    "must be finite and >= min = " + FormatNumber(d.min));
    }
    if (method == SamplingMethod::kGrid && d.count < 1) {
      return Refuse(why, IndexedField("dimensions", i, "count"), d.count, "must be >= 1");
    }
  }
  if (method != SamplingMethod::kGrid && samples < 1) {
    return Refuse(why, "samples", static_cast<double>(samples), "must be >= 1");
  }
  if (method == SamplingMethod::kSobol && dimensions.size() > 32) {
    return Refuse(why, "dimensions", static_cast<double>(dimensions.size()),
                  "Sobol sampling supports at most 32 parameters");
  }
  return true;
}

std::uint64_t SweepPlan::DesignCount() const {
  if (method != SamplingMethod::kGrid) return samples;
  std::uint64_t n = 1;
  for (const auto& d : dimensions) {
    const auto c = static_cast<std::uint64_t>(std::max(d.count, 1));
    if (n > std::numeric_limits<std::uint64_t>::max() / c) {
      return std::numeric_limits<std::uint64_t>::max();
    }
    n *= c;
  }
  return n;
}

bool Shard::Validate(Refusal* why) const {
  if (count < 1) return Refuse(why, "shard.count", static_cast<double>(count), "must be >= 1");
  if (index >= count) {
    return Refuse(why, "shard.index", static_cast<double>(index),
                  "must be below shard.count = " + std::to_string(count));
  }
  return true;
}

std::vector<double> GridDesign(const SweepPlan& plan, std::uint64_t i) {
  std::vector<double> point;
  GridDesignInto(plan, i, &point);
  return point;
}

void GridDesignInto(const SweepPlan& plan, std::uint64_t i, std::vector<double>* out) {
  std::vector<double>& point = *out;
  point.resize(plan.dimensions.size());
  for (std::size_t k = plan.dimensions.size(); k-- > 0;) {
    const SweepDimension& d = plan.dimensions[k];
    const std::uint64_t c = GridCountOf(d);
    const std::uint64_t j = i % c;
    i /= c;
    point[k] = GridValueOf(d, c, j);
  }
}

namespace {

// The Latin hypercube table of `plan`: design i's values at [i * dims, (i + 1) * dims).
// Dimension by dimension: a Fisher-Yates shuffle of the strata, then one jitter per design.
std::vector<double> LatinHypercubeTable(const SweepPlan& plan) {
  const std::size_t dims = plan.dimensions.size();
  const auto n = static_cast<std::size_t>(plan.DesignCount());
  std::mt19937_64 rng(plan.seed);
  std::vector<double> table(n * dims);
  std::vector<std::uint64_t> strata(n);
  for (std::size_t k = 0; k < dims; ++k) {
    std::iota(strata.begin(), strata.end(), std::uint64_t{0});
    for (std::uint64_t i = n; i > 1; --i) {  // Fisher-Yates
      std::swap(strata[static_cast<std::size_t>(i - 1)],
                strata[static_cast<std::size_t>(Below(rng, i))]);
    }
    for (std::size_t i = 0; i < n; ++i) {
      const double t = (static_cast<double>(strata[i]) + Unit(rng)) / static_cast<double>(n);
      table[i * dims + k] = Lerp(plan.dimensions[k], t);
    }
  }
  return table;
}

}  // namespace

struct DesignSequence::SobolState {
  explicit SobolState(std::size_t dims) : engine(dims) {}
  boost::random::sobol engine;
  std::uint64_t next = 0;  // the design index the engine gives next
};

DesignSequence::DesignSequence(const SweepPlan& plan) : plan_(plan) {
  if (plan_.method == SamplingMethod::kLatinHypercube) {
    table_ = std::make_shared<const std::vector<double>>(LatinHypercubeTable(plan_));
  } else if (plan_.method == SamplingMethod::kSobol) {
    sobol_ = std::make_unique<SobolState>(plan_.dimensions.size());
    // Boost's sequence starts after the origin at (1/2, ..., 1/2); design 0 is point `seed`.
    sobol_->engine.seed(static_cast<boost::uintmax_t>(plan_.seed));
  }
}

DesignSequence::DesignSequence(const DesignSequence& other)
    : plan_(other.plan_),
      table_(other.table_),
      sobol_(other.sobol_ ? std::make_unique<SobolState>(*other.sobol_) : nullptr) {}

DesignSequence& DesignSequence::operator=(const DesignSequence& other) {
  if (this != &other) *this = DesignSequence(other);
  return *this;
}

DesignSequence::DesignSequence(DesignSequence&&) noexcept = default;
DesignSequence& DesignSequence::operator=(DesignSequence&&) noexcept = default;
DesignSequence::~DesignSequence() = default;

void DesignSequence::DesignInto(std::uint64_t i, std::vector<double>* out) { *out = Design(i); }

const std::vector<double>& DesignSequence::Design(std::uint64_t i) {
  const std::size_t dims = plan_.dimensions.size();
  switch (plan_.method) {
    case SamplingMethod::kGrid:
      // A block's designs come in index order: each one's values follow from the last one's
      // by a step of its digits, each value computed as GridDesignInto computes it.
      if (grid_set_ && i == grid_next_) {
        StepGrid();
      } else {
        SeekGrid(i);
      }
      grid_next_ = i + 1;
      break;
    case SamplingMethod::kLatinHypercube: {
      const double* row = table_->data() + static_cast<std::size_t>(i) * dims;
      point_.assign(row, row + dims);
      break;
    }
    case SamplingMethod::kSobol: {
      SobolState& s = *sobol_;
      // A jump costs one Gray-code update per bit of the index: only when not sequential.
      if (s.next != i) s.engine.seed(static_cast<boost::uintmax_t>(plan_.seed + i));
      const double scale = 1.0 / (static_cast<double>(boost::random::sobol::max()) + 1.0);
      point_.resize(dims);
      for (std::size_t k = 0; k < dims; ++k) {
        point_[k] = Lerp(plan_.dimensions[k], static_cast<double>(s.engine()) * scale);
      }
      s.next = i + 1;
      break;
    }
  }
  return point_;
}

void DesignSequence::SeekGrid(std::uint64_t i) {
  const std::size_t dims = plan_.dimensions.size();
  grid_digits_.resize(dims);
  point_.resize(dims);
  for (std::size_t k = dims; k-- > 0;) {  // as GridDesignInto
    const SweepDimension& d = plan_.dimensions[k];
    const std::uint64_t c = GridCountOf(d);
    grid_digits_[k] = i % c;
    i /= c;
    point_[k] = GridValueOf(d, c, grid_digits_[k]);
  }
  grid_set_ = true;
}

void DesignSequence::StepGrid() {
  // The last digit moves on by one; a digit that reaches its count wraps to 0 and carries.
  for (std::size_t k = grid_digits_.size(); k-- > 0;) {
    const SweepDimension& d = plan_.dimensions[k];
    const std::uint64_t c = GridCountOf(d);
    std::uint64_t& j = grid_digits_[k];
    j = j + 1 == c ? 0 : j + 1;
    point_[k] = GridValueOf(d, c, j);
    if (j != 0) return;
  }
}

std::vector<std::vector<double>> GenerateDesigns(const SweepPlan& plan) {
  const std::uint64_t n = plan.DesignCount();
  std::vector<std::vector<double>> designs(static_cast<std::size_t>(n));
  DesignSequence sequence(plan);
  for (std::uint64_t i = 0; i < n; ++i)
    sequence.DesignInto(i, &designs[static_cast<std::size_t>(i)]);
  return designs;
}

std::vector<std::size_t> ParetoFront(const std::vector<std::vector<double>>& points,
                                     const std::vector<Sense>& senses) {
  // Orient every objective as "larger is better".
  auto value = [&](std::size_t i, std::size_t k) {
    return senses[k] == Sense::kMaximize ? points[i][k] : -points[i][k];
  };
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < points.size(); ++i) {
    bool finite = points[i].size() == senses.size();
    for (double v : points[i]) finite = finite && std::isfinite(v);
    if (finite) order.push_back(i);
  }
  // Lexicographically best first: a point can only be dominated by one before
  // it, and (by transitivity) then by one already on the front. O(n |front|).
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    for (std::size_t k = 0; k < senses.size(); ++k) {
      if (value(a, k) != value(b, k)) return value(a, k) > value(b, k);
    }
    return a < b;
  });
  std::vector<std::size_t> front;
  if (senses.size() == 2) {
    // Two objectives, O(n log n): in this order a point is dominated exactly when a point of a
    // larger first value has a second value at least as large (best_before), or one of the same
    // first value a larger second value (the group's first, sorted before it).
    double best_before = -std::numeric_limits<double>::infinity();
    for (std::size_t g = 0; g < order.size();) {
      const double first = value(order[g], 0);
      const double group_max = value(order[g], 1);
      std::size_t h = g;
      for (; h < order.size() && value(order[h], 0) == first; ++h) {
        const double second = value(order[h], 1);
        if (!(best_before >= second) && !(group_max > second)) front.push_back(order[h]);
      }
      best_before = std::max(best_before, group_max);
      g = h;
    }
    std::sort(front.begin(), front.end());
    return front;
  }
  for (const std::size_t i : order) {
    bool dominated = false;
    for (const std::size_t j : front) {
      bool all_at_least = true;
      bool one_better = false;
      for (std::size_t k = 0; k < senses.size(); ++k) {
        if (value(j, k) < value(i, k)) all_at_least = false;
        if (value(j, k) > value(i, k)) one_better = true;
      }
      if (all_at_least && one_better) {
        dominated = true;
        break;
      }
    }
    if (!dominated) front.push_back(i);
  }
  std::sort(front.begin(), front.end());
  return front;
}

}  // namespace sweetspot::core
