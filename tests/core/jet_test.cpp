// core/numerics/jet.hpp: every operation's value, gradient and Hessian against the derivatives
// worked out by hand (exact up to rounding, so to 1e-14 relative), first- and second-order.
#include "core/numerics/jet.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>

namespace sweetspot::core {
namespace {

using JetTestSecond = jet::Jet<2, true>;
using JetTestFirst = jet::Jet<2, false>;

// A first-order Jet stores its value and gradient only.
static_assert(sizeof(jet::Jet<5, false>) == 6 * sizeof(double));
static_assert(sizeof(jet::Jet<2, true>) == 7 * sizeof(double));

constexpr double kJetTestX = 1.3;
constexpr double kJetTestY = 0.7;

// Expects f's value, gradient and Hessian (h00, h01, h11) to match, to 1e-14 relative.
void ExpectJetTestEqual(const JetTestSecond& f, double v, std::array<double, 2> g,
                        std::array<double, 3> h) {
  auto near = [](double got, double want) {
    EXPECT_NEAR(got, want, 1e-14 * std::max(1.0, std::abs(want)));
  };
  near(f.v, v);
  near(f.g[0], g[0]);
  near(f.g[1], g[1]);
  near(f.h[0], h[0]);
  near(f.h[1], h[1]);
  near(f.h[2], h[1]);  // symmetric
  near(f.h[3], h[2]);
}

TEST(Jet, ProductsAndQuotients) {
  const JetTestSecond x = JetTestSecond::Variable(kJetTestX, 0);
  const JetTestSecond y = JetTestSecond::Variable(kJetTestY, 1);
  const double a = kJetTestX, b = kJetTestY;
  ExpectJetTestEqual(x * y, a * b, {b, a}, {0.0, 1.0, 0.0});
  ExpectJetTestEqual((x + y) * (x - y), a * a - b * b, {2 * a, -2 * b}, {2.0, 0.0, -2.0});
  ExpectJetTestEqual(x / y, a / b, {1 / b, -a / (b * b)}, {0.0, -1 / (b * b), 2 * a / (b * b * b)});
  ExpectJetTestEqual(3.0 / x, 3 / a, {-3 / (a * a), 0.0}, {6 / (a * a * a), 0.0, 0.0});
  ExpectJetTestEqual(x * y / 4.0, a * b / 4, {b / 4, a / 4}, {0.0, 0.25, 0.0});
}

TEST(Jet, SumsDifferencesAndScalings) {
  const JetTestSecond x = JetTestSecond::Variable(kJetTestX, 0);
  const JetTestSecond y = JetTestSecond::Variable(kJetTestY, 1);
  const double a = kJetTestX, b = kJetTestY;
  // 2 - 3x + y/4 - (x - 1) + (1 + y) - 0.5 x - y, then + xy - xy (compound assignments).
  JetTestSecond f = 2.0 - 3.0 * x + y / 4.0 - (x - 1.0) + (1.0 + y) - x * 0.5 + (-y);
  f += x * y;
  f -= y * x;
  f *= 2.0;
  const double v = 2 * (2 - 3 * a + b / 4 - (a - 1) + (1 + b) - 0.5 * a - b);
  ExpectJetTestEqual(f, v, {2 * (-4.5), 2 * 0.25}, {0.0, 0.0, 0.0});
}

TEST(Jet, SqrtAndPow) {
  const JetTestSecond x = JetTestSecond::Variable(kJetTestX, 0);
  const JetTestSecond y = JetTestSecond::Variable(kJetTestY, 1);
  const double a = kJetTestX, b = kJetTestY;
  const double r = std::sqrt(a * b);
  ExpectJetTestEqual(jet::Sqrt(x * y), r, {0.5 * b / r, 0.5 * a / r},
                     {-0.25 * b * b / (r * r * r), 0.25 / r, -0.25 * a * a / (r * r * r)});
  ExpectJetTestEqual(jet::Pow(x, 2.5), std::pow(a, 2.5), {2.5 * std::pow(a, 1.5), 0.0},
                     {3.75 * std::sqrt(a), 0.0, 0.0});
}

TEST(Jet, FirstOrderMatchesSecondOrderGradient) {
  const JetTestFirst x = JetTestFirst::Variable(kJetTestX, 0);
  const JetTestFirst y = JetTestFirst::Variable(kJetTestY, 1);
  const JetTestSecond xs = JetTestSecond::Variable(kJetTestX, 0);
  const JetTestSecond ys = JetTestSecond::Variable(kJetTestY, 1);
  const JetTestFirst f = jet::Sqrt(x * y + 2.0) / (1.0 - x) - 0.5 * y * y;
  const JetTestSecond fs = jet::Sqrt(xs * ys + 2.0) / (1.0 - xs) - 0.5 * ys * ys;
  EXPECT_DOUBLE_EQ(f.v, fs.v);
  EXPECT_DOUBLE_EQ(f.g[0], fs.g[0]);
  EXPECT_DOUBLE_EQ(f.g[1], fs.g[1]);
}

}  // namespace
}  // namespace sweetspot::core
