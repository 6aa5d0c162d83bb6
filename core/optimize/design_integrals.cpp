// The design code's parametrisation and mass integrals with their exact first and second
// derivatives (design_integrals.hpp): the sums of one segment and of the fill, and
// ComputeIntegrals over the whole bat. Split from design_model.cpp (issue 33, item 6).
#include "core/optimize/design_integrals.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "core/bat/geometry_integrals.hpp"
#include "core/numerics/jet.hpp"
#include "core/numerics/limits.hpp"
#include "core/units.hpp"

namespace sweetspot::core {
namespace {

// Integrals of one segment or of the fill, in the scalar type T.
template <typename T>
struct Sums {
  T mass;  // kg
  T s1;    // first moment about c0, kg m
  T s2;    // second moment about c0 (+ own moments when rigid), kg m^2
};

template <typename T>
Sums<T> SegmentSums(const T& xa, const T& xb, const T& ra, const T& rb, const T& wall, const T& rho,
                    bool hollow, bool rigid, double c0) {
  const T h = xb - xa;
  const T d = 0.5 * (xa + xb) - c0;
  const geometry::SegmentIntegrals<T> s = geometry::IntegrateSegment<T>(h, ra, rb, wall, hollow);
  T q2 = (d * d) * s.volume + 2.0 * d * s.first + s.second;
  if (rigid) q2 += s.disk;
  return {rho * s.volume, rho * (d * s.volume + s.first), rho * q2};
}

template <typename T>
Sums<T> FillSums(const T& radius, const T& depth, const T& length, const T& fill_density,
                 const T& rho, bool hollow, bool rigid, double c0) {
  const T excess = hollow ? fill_density : fill_density - rho;
  const T volume = kPi * radius * radius * depth;
  const T e = length - 0.5 * depth - c0;
  T own = e * e + depth * depth * (1.0 / 12.0);
  if (rigid) own += 0.25 * radius * radius;
  const T mass = excess * volume;
  return {mass, mass * e, mass * own};
}

}  // namespace

namespace {

// The local parameters of segment i and of the fill, with their chain-rule coefficients.
struct LocalMap {
  std::array<int, 6> index{};
  std::array<double, 6> coefficient{};
  int size = 0;
};

LocalMap SegmentMap(const DesignParameterLayout& lay, int i) {
  LocalMap m;
  m.index = {lay.KnotPosition(i),   lay.KnotPosition(i + 1), lay.KnotRadius(i),
             lay.KnotRadius(i + 1), lay.WallThickness(),     lay.Density()};
  m.coefficient = {1, 1, 1, 1, 1, 1};
  m.size = 6;
  return m;
}

LocalMap FillMap(const DesignParameterLayout& lay) {
  LocalMap m;
  // Local variables: bore radius (= diameter / 2), depth, L, fill density, bat density.
  m.index = {lay.FillDiameter(), lay.FillDepth(), lay.KnotPosition(lay.num_knots - 1),
             lay.FillDensity(),  lay.Density(),   0};
  m.coefficient = {0.5, 1, 1, 1, 1, 0};
  m.size = 5;
  return m;
}

}  // namespace

// The parametrisation and the integrals (design_integrals.hpp).
namespace design_detail {

std::vector<double> ThreeSegmentParameters(const Bat& base, const ThreeSegmentShape& s) {
  Bat four = base;
  four.knots = {{0.0, s.handle_radius_m},
                {s.taper_start_m, s.handle_radius_m},
                {s.taper_end_m, s.barrel_radius_m},
                {s.length_m, s.barrel_radius_m}};
  const Eigen::VectorXd p = DesignParameters(four);
  return {p.data(), p.data() + p.size()};
}

ThreeSegmentShape ThreeSegmentShapeAt(const std::vector<double>& t, ThreeSegmentShape shape) {
  const DesignParameterLayout lay{4};
  shape.length_m = t[static_cast<std::size_t>(lay.KnotPosition(3))];
  shape.handle_radius_m = t[static_cast<std::size_t>(lay.KnotRadius(0))];
  shape.barrel_radius_m = t[static_cast<std::size_t>(lay.KnotRadius(2))];
  // Solvers meet x1 <= x2 <= L and 0 <= x1 to their tolerance: remove that round-off.
  shape.taper_start_m = std::max(t[static_cast<std::size_t>(lay.KnotPosition(1))], 0.0);
  shape.taper_end_m = std::min(t[static_cast<std::size_t>(lay.KnotPosition(2))], shape.length_m);
  shape.taper_start_m = std::min(shape.taper_start_m, shape.taper_end_m);
  return shape;
}

std::vector<int> DesignParametersOf(const DesignVariableRef& ref,
                                    const DesignParameterLayout& lay) {
  switch (ref.kind) {
    case DesignVariableKind::kKnotRadius:
      return {lay.KnotRadius(ref.knot)};
    case DesignVariableKind::kKnotPosition:
      return {lay.KnotPosition(ref.knot)};
    case DesignVariableKind::kLength:
      return {lay.KnotPosition(3)};
    case DesignVariableKind::kHandleRadius:
      return {lay.KnotRadius(0), lay.KnotRadius(1)};
    case DesignVariableKind::kBarrelRadius:
      return {lay.KnotRadius(2), lay.KnotRadius(3)};
    case DesignVariableKind::kTaperStart:
      return {lay.KnotPosition(1)};
    case DesignVariableKind::kTaperEnd:
      return {lay.KnotPosition(2)};
    case DesignVariableKind::kDensity:
      return {lay.Density()};
    case DesignVariableKind::kWallThickness:
      return {lay.WallThickness()};
    case DesignVariableKind::kFillDiameter:
      return {lay.FillDiameter()};
    case DesignVariableKind::kFillDepth:
      return {lay.FillDepth()};
    case DesignVariableKind::kFillDensity:
      return {lay.FillDensity()};
  }
  return {};
}

void ComputeIntegrals(const IntegralContext& c, int n, bool gradients, Integrals* out) {
  const DesignParameterLayout lay{c.num_knots};
  out->p = {0.0, 0.0, 0.0, c.t[static_cast<std::size_t>(lay.KnotPosition(c.num_knots - 1))]};
  if (gradients) {
    out->dp = Eigen::Matrix<double, 4, Eigen::Dynamic>::Zero(4, n);
    const auto l_idx = static_cast<std::size_t>(lay.KnotPosition(c.num_knots - 1));
    const int l_var = c.parameter_variable[l_idx];
    if (l_var >= 0) out->dp(3, l_var) = c.parameter_scale[l_idx];
  }
  auto at = [&](int idx) { return c.t[static_cast<std::size_t>(idx)]; };
  for (int i = 0; i + 1 < c.num_knots; ++i) {
    const LocalMap map = SegmentMap(lay, i);
    if (!gradients) {
      const Sums<double> s = SegmentSums<double>(
          at(map.index[0]), at(map.index[1]), at(map.index[2]), at(map.index[3]), at(map.index[4]),
          at(map.index[5]), c.hollow, c.rigid, c.c0);
      out->p[0] += s.mass;
      out->p[1] += s.s1;
      out->p[2] += s.s2;
      continue;
    }
    using J = jet::Jet<6, false>;
    std::array<J, 6> v;
    for (int a = 0; a < 6; ++a)
      v[static_cast<std::size_t>(a)] = J::Variable(at(map.index[static_cast<std::size_t>(a)]), a);
    const Sums<J> s = SegmentSums<J>(v[0], v[1], v[2], v[3], v[4], v[5], c.hollow, c.rigid, c.c0);
    out->p[0] += s.mass.v;
    out->p[1] += s.s1.v;
    out->p[2] += s.s2.v;
    for (int a = 0; a < 6; ++a) {
      const auto idx = static_cast<std::size_t>(map.index[static_cast<std::size_t>(a)]);
      const int j = c.parameter_variable[idx];
      if (j < 0) continue;
      const double k = c.parameter_scale[idx];
      out->dp(0, j) += k * s.mass.g[static_cast<std::size_t>(a)];
      out->dp(1, j) += k * s.s1.g[static_cast<std::size_t>(a)];
      out->dp(2, j) += k * s.s2.g[static_cast<std::size_t>(a)];
    }
  }
  if (c.has_fill) {
    const LocalMap map = FillMap(lay);
    std::array<double, 5> local;
    for (int a = 0; a < 5; ++a) {
      local[static_cast<std::size_t>(a)] =
          map.coefficient[static_cast<std::size_t>(a)] * at(map.index[static_cast<std::size_t>(a)]);
    }
    if (!gradients) {
      const Sums<double> s = FillSums<double>(local[0], local[1], local[2], local[3], local[4],
                                              c.hollow, c.rigid, c.c0);
      out->p[0] += s.mass;
      out->p[1] += s.s1;
      out->p[2] += s.s2;
    } else {
      using J = jet::Jet<5, false>;
      std::array<J, 5> v;
      for (int a = 0; a < 5; ++a)
        v[static_cast<std::size_t>(a)] = J::Variable(local[static_cast<std::size_t>(a)], a);
      const Sums<J> s = FillSums<J>(v[0], v[1], v[2], v[3], v[4], c.hollow, c.rigid, c.c0);
      out->p[0] += s.mass.v;
      out->p[1] += s.s1.v;
      out->p[2] += s.s2.v;
      for (int a = 0; a < 5; ++a) {
        const auto idx = static_cast<std::size_t>(map.index[static_cast<std::size_t>(a)]);
        const int j = c.parameter_variable[idx];
        if (j < 0) continue;
        const double k = map.coefficient[static_cast<std::size_t>(a)] * c.parameter_scale[idx];
        out->dp(0, j) += k * s.mass.g[static_cast<std::size_t>(a)];
        out->dp(1, j) += k * s.s1.g[static_cast<std::size_t>(a)];
        out->dp(2, j) += k * s.s2.g[static_cast<std::size_t>(a)];
      }
    }
  }
}

// Adds sum_c w_c d2P_c/dx2 into *h (n x n).
void AddIntegralHessian(const IntegralContext& c, const std::array<double, 3>& w,
                        Eigen::MatrixXd* h) {
  VisitIntegralHessian(c, w, [h](int ja, int jb, double v) { (*h)(ja, jb) += v; });
}

// Visits sum_c w_c d2P_c/dx2 term by term.
void VisitIntegralHessian(const IntegralContext& c, const std::array<double, 3>& w,
                          const std::function<void(int, int, double)>& add) {
  const DesignParameterLayout lay{c.num_knots};
  auto at = [&](int idx) { return c.t[static_cast<std::size_t>(idx)]; };
  auto scatter = [&](const LocalMap& map, const auto& combined, int size) {
    // Each local parameter is coefficient * parameter, each parameter scale * its variable:
    // a term of the Hessian carries both factors of both.
    for (int a = 0; a < size; ++a) {
      const auto ia = static_cast<std::size_t>(map.index[static_cast<std::size_t>(a)]);
      const int ja = c.parameter_variable[ia];
      if (ja < 0) continue;
      const double ka = map.coefficient[static_cast<std::size_t>(a)] * c.parameter_scale[ia];
      for (int b = 0; b < size; ++b) {
        const auto ib = static_cast<std::size_t>(map.index[static_cast<std::size_t>(b)]);
        const int jb = c.parameter_variable[ib];
        if (jb < 0) continue;
        const double kb = map.coefficient[static_cast<std::size_t>(b)] * c.parameter_scale[ib];
        add(ja, jb, ka * kb * combined.h[static_cast<std::size_t>(a * size + b)]);
      }
    }
  };
  for (int i = 0; i + 1 < c.num_knots; ++i) {
    const LocalMap map = SegmentMap(lay, i);
    // The local parameters that are variables: none, no term; at most two (the knot radii of a
    // profile design), a jet over those alone (the others constants: the same second
    // derivatives, 4 entries instead of 36); otherwise all six.
    std::array<int, 6> active{};
    int count = 0;
    for (int a = 0; a < 6; ++a) {
      if (c.parameter_variable[static_cast<std::size_t>(map.index[static_cast<std::size_t>(a)])] >=
          0) {
        active[static_cast<std::size_t>(count++)] = a;
      }
    }
    if (count == 0) continue;
    if (count <= 2) {
      using J2 = jet::Jet<2, true>;
      std::array<J2, 6> v;
      for (int a = 0; a < 6; ++a) v[static_cast<std::size_t>(a)] = J2(at(map.index[static_cast<std::size_t>(a)]));
      LocalMap reduced;
      for (int q = 0; q < count; ++q) {
        const auto a = static_cast<std::size_t>(active[static_cast<std::size_t>(q)]);
        v[a] = J2::Variable(at(map.index[a]), q);
        reduced.index[static_cast<std::size_t>(q)] = map.index[a];
        reduced.coefficient[static_cast<std::size_t>(q)] = map.coefficient[a];
      }
      // A single variable: the second slot is a constant, its entries 0 (scatter skips none,
      // so point it at the same parameter with a zero coefficient).
      if (count == 1) {
        reduced.index[1] = reduced.index[0];
        reduced.coefficient[1] = 0.0;
      }
      const Sums<J2> s =
          SegmentSums<J2>(v[0], v[1], v[2], v[3], v[4], v[5], c.hollow, c.rigid, c.c0);
      const J2 combined = w[0] * s.mass + w[1] * s.s1 + w[2] * s.s2;
      scatter(reduced, combined, 2);
      continue;
    }
    using J = jet::Jet<6, true>;
    std::array<J, 6> v;
    for (int a = 0; a < 6; ++a)
      v[static_cast<std::size_t>(a)] = J::Variable(at(map.index[static_cast<std::size_t>(a)]), a);
    const Sums<J> s = SegmentSums<J>(v[0], v[1], v[2], v[3], v[4], v[5], c.hollow, c.rigid, c.c0);
    const J combined = w[0] * s.mass + w[1] * s.s1 + w[2] * s.s2;
    scatter(map, combined, 6);
  }
  if (c.has_fill) {
    const LocalMap map = FillMap(lay);
    using J = jet::Jet<5, true>;
    std::array<J, 5> v;
    for (int a = 0; a < 5; ++a) {
      v[static_cast<std::size_t>(a)] = J::Variable(
          map.coefficient[static_cast<std::size_t>(a)] * at(map.index[static_cast<std::size_t>(a)]),
          a);
    }
    const Sums<J> s = FillSums<J>(v[0], v[1], v[2], v[3], v[4], c.hollow, c.rigid, c.c0);
    const J combined = w[0] * s.mass + w[1] * s.s1 + w[2] * s.s2;
    scatter(map, combined, 5);
  }
}

}  // namespace design_detail

}  // namespace sweetspot::core
