#include "core/explore/sampling.hpp"

#include <gtest/gtest.h>
#include <boost/random/sobol.hpp>

#include "tests/refusal_text.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <set>

namespace sweetspot::core {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace sampling_test {
namespace {

TEST(SamplingTest, GridIsTheRowMajorProductWithExactEnds) {
  SweepPlan plan;
  plan.dimensions = {{0.0, 1.0, 3}, {10.0, 20.0, 2}};
  ASSERT_TRUE(plan.Validate(nullptr));
  EXPECT_EQ(plan.DesignCount(), 6u);
  const auto designs = GenerateDesigns(plan);
  const std::vector<std::vector<double>> expected = {{0.0, 10.0}, {0.0, 20.0}, {0.5, 10.0},
                                                     {0.5, 20.0}, {1.0, 10.0}, {1.0, 20.0}};
  EXPECT_EQ(designs, expected);  // exact: min + (max - min) * j / (c - 1) hits the ends exactly
  for (std::uint64_t i = 0; i < 6; ++i) EXPECT_EQ(GridDesign(plan, i), expected[i]);
}

TEST(SamplingTest, LatinHypercubeHasOnePointPerStratumAndIsSeeded) {
  SweepPlan plan;
  plan.method = SamplingMethod::kLatinHypercube;
  plan.dimensions = {{0.0, 1.0, 1}, {-5.0, 5.0, 1}, {2.0, 3.0, 1}};
  plan.samples = 50;
  plan.seed = 42;
  const auto a = GenerateDesigns(plan);
  ASSERT_EQ(a.size(), 50u);
  for (std::size_t k = 0; k < 3; ++k) {
    std::set<int> strata;
    for (const auto& p : a) {
      const auto& d = plan.dimensions[k];
      const double t = (p[k] - d.min) / (d.max - d.min);
      ASSERT_GE(t, 0.0);
      ASSERT_LT(t, 1.0);
      strata.insert(static_cast<int>(t * 50));
    }
    EXPECT_EQ(strata.size(), 50u) << "dimension " << k;  // every stratum exactly once
  }
  EXPECT_EQ(GenerateDesigns(plan), a);  // same seed, same designs, bit for bit
  plan.seed = 43;
  EXPECT_NE(GenerateDesigns(plan), a);
}

TEST(SamplingTest, SobolMatchesTheKnownFirstPointsAndSkipsBySeed) {
  SweepPlan plan;
  plan.method = SamplingMethod::kSobol;
  plan.dimensions = {{0.0, 1.0, 1}, {0.0, 1.0, 1}};
  plan.samples = 3;
  const auto a = GenerateDesigns(plan);
  // The 2-D Sobol sequence after the origin: (1/2, 1/2), (3/4, 1/4), (1/4, 3/4).
  const std::vector<std::vector<double>> expected = {{0.5, 0.5}, {0.75, 0.25}, {0.25, 0.75}};
  EXPECT_EQ(a, expected);  // dyadic rationals: exact in double
  plan.seed = 1;
  plan.samples = 2;
  const auto b = GenerateDesigns(plan);
  EXPECT_EQ(b[0], expected[1]);
  EXPECT_EQ(b[1], expected[2]);
}

// Explore's workers take designs by index in blocks, each from its own copy: every access
// order gives design i of the sequential sequence, bit for bit. Sobol is checked against
// Boost's generator read sequentially after discarding `seed` points (the drawing this class
// replaced), LHS against GenerateDesigns.
TEST(SamplingTest, DesignSequenceGivesDesignIInAnyOrder) {
  SweepPlan plan;
  plan.method = SamplingMethod::kSobol;
  plan.dimensions = {{0.0, 1.0, 1}, {-2.0, 3.0, 1}, {10.0, 11.0, 1}};
  plan.samples = 3000;
  plan.seed = 17;
  boost::random::sobol engine(3);
  engine.discard(static_cast<boost::uintmax_t>(plan.seed * 3));
  const double scale = 1.0 / (static_cast<double>(boost::random::sobol::max()) + 1.0);
  std::vector<std::vector<double>> reference(plan.samples, std::vector<double>(3));
  for (auto& point : reference) {
    for (std::size_t k = 0; k < 3; ++k) {
      const SweepDimension& d = plan.dimensions[k];
      point[k] = d.min + (d.max - d.min) * (static_cast<double>(engine()) * scale);
    }
  }
  EXPECT_EQ(GenerateDesigns(plan), reference);
  std::vector<std::uint64_t> order(plan.samples);
  std::iota(order.begin(), order.end(), std::uint64_t{0});
  std::shuffle(order.begin(), order.end(), std::mt19937_64(5));
  const DesignSequence prototype(plan);
  DesignSequence a = prototype;
  DesignSequence b = prototype;
  std::vector<double> point;
  for (std::size_t j = 0; j < order.size(); ++j) {
    (j % 2 == 0 ? a : b).DesignInto(order[j], &point);  // jumps, alternating copies
    ASSERT_EQ(point, reference[order[j]]) << "design " << order[j];
  }
  for (std::uint64_t i = 1000; i < 1100; ++i) {  // a block in order: sequential draws
    a.DesignInto(i, &point);
    ASSERT_EQ(point, reference[i]) << "design " << i;
  }

  plan.method = SamplingMethod::kLatinHypercube;
  const auto lhs = GenerateDesigns(plan);
  DesignSequence c(plan);
  for (std::uint64_t i = plan.samples; i-- > 0;) {
    c.DesignInto(i, &point);
    ASSERT_EQ(point, lhs[i]) << "design " << i;
  }

  // A grid steps from the last design to the next (carries through a dimension of one value
  // too), and seeks any other: GridDesign's values either way.
  plan.method = SamplingMethod::kGrid;
  plan.dimensions = {{0.1, 0.7, 3}, {-2.0, 3.0, 1}, {0.45, 0.7, 7}, {1.0, 2.0, 2}};
  const std::uint64_t n = plan.DesignCount();
  DesignSequence grid(plan);
  for (const std::uint64_t first : {std::uint64_t{0}, std::uint64_t{5}, std::uint64_t{13}}) {
    for (std::uint64_t i = first; i < n; ++i) {
      grid.DesignInto(i, &point);
      ASSERT_EQ(point, GridDesign(plan, i)) << "design " << i;
    }
  }
  for (std::uint64_t i = n; i-- > 0;) {
    grid.DesignInto(i, &point);
    ASSERT_EQ(point, GridDesign(plan, i)) << "design " << i;
  }
}

TEST(SamplingTest, ShardsPartitionTheDesigns) {
  for (std::uint64_t count : {1u, 2u, 3u, 7u}) {
    std::vector<int> owners(100, 0);
    for (std::uint64_t index = 0; index < count; ++index) {
      const Shard shard{index, count};
      ASSERT_TRUE(shard.Validate(nullptr));
      for (std::uint64_t i = 0; i < 100; ++i) owners[i] += shard.Contains(i) ? 1 : 0;
    }
    EXPECT_TRUE(std::all_of(owners.begin(), owners.end(), [](int n) { return n == 1; }));
  }
  std::string why;
  EXPECT_FALSE(Validates(Shard{3, 3}, &why));
  EXPECT_EQ(why, "shard.index = 3: must be below shard.count = 3");
}

TEST(SamplingTest, ParetoFrontOfAKnownSet) {
  // Maximise the first, minimise the second.
  const std::vector<std::vector<double>> points = {
      {1.0, 1.0}, {2.0, 2.0}, {2.0, 1.5}, {0.5, 0.5}, {1.5, 3.0}, {2.0, 1.5}, {3.0, std::nan("")}};
  const auto front = ParetoFront(points, {Sense::kMaximize, Sense::kMinimize});
  // {2, 1.5} twice (equal points do not dominate each other), {1, 1}, {0.5, 0.5}.
  EXPECT_EQ(front, (std::vector<std::size_t>{0, 2, 3, 5}));
}

TEST(SamplingTest, ParetoFrontAgreesWithBruteForceOnRandomSets) {
  std::mt19937_64 rng(7);
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<std::vector<double>> points(200, std::vector<double>(3));
    for (auto& p : points) {
      for (double& v : p) v = static_cast<double>(rng() % 20);  // ties on purpose
    }
    const std::vector<Sense> senses = {Sense::kMaximize, Sense::kMinimize, Sense::kMaximize};
    std::vector<std::size_t> brute;
    for (std::size_t i = 0; i < points.size(); ++i) {
      bool dominated = false;
      for (std::size_t j = 0; j < points.size(); ++j) {
        const bool ge = points[j][0] >= points[i][0] && points[j][1] <= points[i][1] &&
                        points[j][2] >= points[i][2];
        const bool gt = points[j][0] > points[i][0] || points[j][1] < points[i][1] ||
                        points[j][2] > points[i][2];
        dominated = dominated || (ge && gt);
      }
      if (!dominated) brute.push_back(i);
    }
    EXPECT_EQ(ParetoFront(points, senses), brute);
  }
}

// Two objectives take the O(n log n) sweep: the same front as the definition, with ties in
// either objective, duplicates, both senses and non-finite values.
TEST(SamplingTest, TwoObjectiveParetoFrontAgreesWithBruteForce) {
  std::mt19937_64 rng(11);
  for (int trial = 0; trial < 40; ++trial) {
    const std::size_t n = trial < 20 ? 200 : 3;
    std::vector<std::vector<double>> points(n, std::vector<double>(2));
    for (auto& p : points) {
      for (double& v : p) v = static_cast<double>(rng() % (trial % 2 == 0 ? 6 : 1000));
    }
    if (trial % 5 == 0) points[0][1] = std::nan("");
    const std::vector<Sense> senses = {trial % 3 == 0 ? Sense::kMinimize : Sense::kMaximize,
                                       trial % 4 == 0 ? Sense::kMaximize : Sense::kMinimize};
    const auto good = [&](std::size_t j, std::size_t k) {
      return senses[k] == Sense::kMaximize ? points[j][k] : -points[j][k];
    };
    std::vector<std::size_t> brute;
    for (std::size_t i = 0; i < n; ++i) {
      bool dominated = !std::isfinite(points[i][0]) || !std::isfinite(points[i][1]);
      for (std::size_t j = 0; j < n; ++j) {
        if (!std::isfinite(points[j][0]) || !std::isfinite(points[j][1])) continue;
        const bool ge = good(j, 0) >= good(i, 0) && good(j, 1) >= good(i, 1);
        const bool gt = good(j, 0) > good(i, 0) || good(j, 1) > good(i, 1);
        dominated = dominated || (ge && gt);
      }
      if (!dominated) brute.push_back(i);
    }
    EXPECT_EQ(ParetoFront(points, senses), brute) << "trial " << trial;
  }
}

TEST(SamplingTest, InvalidPlansAreNamed) {
  SweepPlan plan;
  std::string why;
  EXPECT_FALSE(Validates(plan, &why));
  EXPECT_EQ(why, "dimensions = 0: must have 1 to 32 parameters");
  plan.dimensions = {{1.0, 0.0, 2}};
  EXPECT_FALSE(Validates(plan, &why));
  EXPECT_EQ(why, "dimensions[0].max = 0: must be finite and >= min = 1");
  plan.dimensions = {{0.0, 1.0, 2}};
  plan.method = SamplingMethod::kLatinHypercube;
  EXPECT_FALSE(Validates(plan, &why));
  EXPECT_EQ(why, "samples = 0: must be >= 1");
}

}  // namespace
}  // namespace sampling_test
}  // namespace sweetspot::core
