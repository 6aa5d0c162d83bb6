#include "core/sampling.hpp"

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
  const std::uint64_t limit = std::numeric_limits<std::uint64_t>::max() -
                              std::numeric_limits<std::uint64_t>::max() % n;
  std::uint64_t draw;
  do {
    draw = rng();
  } while (draw >= limit);
  return draw % n;
}

double Lerp(const SweepDimension& d, double t) { return d.min + (d.max - d.min) * t; }

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
  for (const auto m : {SamplingMethod::kGrid, SamplingMethod::kLatinHypercube,
                       SamplingMethod::kSobol}) {
    if (name == SamplingMethodName(m)) return m;
  }
  return std::nullopt;
}

bool SweepPlan::IsValid(std::string* why) const {
  return ExplainRefusal(why, [this](Refusal* out) { return Validate(out); });
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

bool Shard::IsValid(std::string* why) const {
  return ExplainRefusal(why, [this](Refusal* out) { return Validate(out); });
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
    const auto c = static_cast<std::uint64_t>(std::max(d.count, 1));
    const std::uint64_t j = i % c;
    i /= c;
    point[k] = c == 1 ? d.min : Lerp(d, static_cast<double>(j) / static_cast<double>(c - 1));
  }
}

std::vector<std::vector<double>> GenerateDesigns(const SweepPlan& plan) {
  const std::size_t dims = plan.dimensions.size();
  const std::uint64_t n = plan.DesignCount();
  std::vector<std::vector<double>> designs;
  designs.reserve(static_cast<std::size_t>(n));
  switch (plan.method) {
    case SamplingMethod::kGrid:
      for (std::uint64_t i = 0; i < n; ++i) designs.push_back(GridDesign(plan, i));
      break;
    case SamplingMethod::kLatinHypercube: {
      std::mt19937_64 rng(plan.seed);
      designs.assign(static_cast<std::size_t>(n), std::vector<double>(dims));
      std::vector<std::uint64_t> strata(static_cast<std::size_t>(n));
      for (std::size_t k = 0; k < dims; ++k) {
        std::iota(strata.begin(), strata.end(), std::uint64_t{0});
        for (std::uint64_t i = n; i > 1; --i) {  // Fisher-Yates
          std::swap(strata[static_cast<std::size_t>(i - 1)],
                    strata[static_cast<std::size_t>(Below(rng, i))]);
        }
        for (std::uint64_t i = 0; i < n; ++i) {
          const double t = (static_cast<double>(strata[static_cast<std::size_t>(i)]) + Unit(rng)) /
                           static_cast<double>(n);
          designs[static_cast<std::size_t>(i)][k] = Lerp(plan.dimensions[k], t);
        }
      }
      break;
    }
    case SamplingMethod::kSobol: {
      boost::random::sobol sobol(dims);
      // Boost's sequence starts after the origin at (1/2, ..., 1/2); skip `seed` points.
      if (plan.seed > 0) sobol.discard(static_cast<boost::uintmax_t>(plan.seed * dims));
      const double scale = 1.0 / (static_cast<double>(boost::random::sobol::max()) + 1.0);
      for (std::uint64_t i = 0; i < n; ++i) {
        std::vector<double> point(dims);
        for (std::size_t k = 0; k < dims; ++k) {
          point[k] = Lerp(plan.dimensions[k], static_cast<double>(sobol()) * scale);
        }
        designs.push_back(std::move(point));
      }
      break;
    }
  }
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
