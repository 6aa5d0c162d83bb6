// Small, independent long double references for the hard cases. They re-implement the same
// closed-form quantities as core by another route (Gauss-Legendre on exact polynomial
// integrands instead of core's per-segment expansions about the midpoint; the textbook
// collision formulas), in long double (64-bit mantissa: 2048 times finer than double), and
// without the subtractions that would cancel (an annulus is (r_o - r_i)(r_o + r_i)).
#pragma once

#include <cmath>
#include <vector>

#include "core/bat/bat.hpp"

namespace sweetspot::hard_cases {

using Real = long double;

/// Mass properties of a bat, in long double.
struct ReferenceProperties {
  Real mass_kg = 0;
  Real balance_point_m = 0;
  Real moi_centroid_kg_m2 = 0;
  Real volume_m3 = 0;  ///< Of material (the bat's and a non-empty fill's).
};

/// The mass properties of `bat` (valid) by 3-point Gauss-Legendre on every interval between
/// the knots and the fill's bottom: the linear density is a polynomial of degree <= 2 there,
/// times (x - C)^2 degree <= 4, and the disks' own moment r^4 degree <= 4, so 3 points (exact
/// to degree 5) integrate them exactly; the only error is long double round-off (~1e-18).
inline ReferenceProperties ReferenceMassProperties(const core::Bat& bat, bool rigid_body) {
  const Real length = bat.knots.back().x_m;
  const bool hollow = bat.wall_thickness_m > 0.0;
  const Real wall = bat.wall_thickness_m;
  const Real rho = bat.material.density_kg_m3;
  const bool has_fill = bat.fill.has_value();
  const Real fill_r = has_fill ? Real(bat.fill->diameter_m) / 2 : 0;
  const Real fill_start = has_fill ? length - Real(bat.fill->depth_m) : length;
  const Real fill_rho = has_fill ? Real(bat.fill->material.density_kg_m3) : 0;
  const Real pi = std::acos(Real(-1));
  // The breakpoints: every knot, and the fill's bottom.
  std::vector<Real> cuts;
  for (const auto& k : bat.knots) cuts.push_back(k.x_m);
  if (has_fill && fill_start > 0 && fill_start < length) {
    for (std::size_t i = 0; i + 1 < cuts.size(); ++i) {
      if (cuts[i] < fill_start && fill_start < cuts[i + 1]) {
        cuts.insert(cuts.begin() + static_cast<long>(i) + 1, fill_start);
        break;
      }
    }
  }
  // Outer radius at x (linear between knots, in long double).
  auto radius = [&](Real x) {
    for (std::size_t i = 0; i + 1 < bat.knots.size(); ++i) {
      const Real a = bat.knots[i].x_m, b = bat.knots[i + 1].x_m;
      if (x <= b || i + 2 == bat.knots.size()) {
        return Real(bat.knots[i].radius_m) +
               (Real(bat.knots[i + 1].radius_m) - Real(bat.knots[i].radius_m)) * (x - a) / (b - a);
      }
    }
    return Real(bat.knots.back().radius_m);
  };
  // Linear density (kg/m), the disks' own moment per length (kg m) and the area of material.
  struct Section {
    Real lambda, mu, area;
  };
  auto section = [&](Real x, bool in_fill) {
    const Real r = radius(x);
    Real inner = 0, width = r;  // the bat's annulus is [inner, r], width = r - inner
    if (hollow) {
      inner = r - wall;
      width = wall;
    } else if (in_fill) {
      inner = fill_r;
      width = r - fill_r;
    }
    const Real annulus = pi * width * (r + inner);  // pi (r^2 - inner^2), no cancellation
    Section s;
    s.area = annulus;
    s.lambda = rho * annulus;
    s.mu = rho * annulus * (r * r + inner * inner) / 4;  // rho pi (r^4 - inner^4) / 4
    if (in_fill && fill_rho > 0) {
      s.area += pi * fill_r * fill_r;
      s.lambda += fill_rho * pi * fill_r * fill_r;
      s.mu += fill_rho * pi * fill_r * fill_r * fill_r * fill_r / 4;
    }
    return s;
  };
  const Real nodes[3] = {-std::sqrt(Real(3) / 5), 0, std::sqrt(Real(3) / 5)};
  const Real weights[3] = {Real(5) / 9, Real(8) / 9, Real(5) / 9};
  auto integrate = [&](auto&& f) {
    Real sum = 0;
    for (std::size_t i = 0; i + 1 < cuts.size(); ++i) {
      const Real a = cuts[i], b = cuts[i + 1];
      const bool in_fill = has_fill && a >= fill_start;
      const Real half = (b - a) / 2, mid = (a + b) / 2;
      for (int g = 0; g < 3; ++g) {
        const Real x = mid + half * nodes[g];
        sum += half * weights[g] * f(x, section(x, in_fill));
      }
    }
    return sum;
  };
  ReferenceProperties out;
  out.mass_kg = integrate([](Real, const Section& s) { return s.lambda; });
  out.volume_m3 = integrate([](Real, const Section& s) { return s.area; });
  const Real first = integrate([](Real x, const Section& s) { return s.lambda * x; });
  out.balance_point_m = first / out.mass_kg;
  const Real c = out.balance_point_m;
  out.moi_centroid_kg_m2 = integrate([&](Real x, const Section& s) {
    return s.lambda * (x - c) * (x - c) + (rigid_body ? s.mu : 0);
  });
  return out;
}

/// The rigid-pivot sweet spot in long double (paper-notes.md section 3): x* = w J / (m (u + S)),
/// S = sqrt(u^2 + w^2 J / m), v2max = ((1 + e) S - (1 - e) u) / 2; x from the pivot.
struct ReferenceSweetSpot {
  Real x_from_pivot_m = 0;
  Real exit_speed_mps = 0;
};
inline ReferenceSweetSpot RigidPivotSweetSpot(Real j, Real m, Real u, Real w, Real e) {
  const Real s = std::sqrt(u * u + w * w * j / m);
  return {w * j / (m * (u + s)), ((1 + e) * s - (1 - e) * u) / 2};
}

/// The rigid-pivot exit speed at x from the pivot: -u + J (1 + e) (u + w x) / (J + m x^2).
inline Real RigidPivotExitSpeed(Real j, Real m, Real u, Real w, Real e, Real x) {
  return -u + j * (1 + e) * (u + w * x) / (j + m * x * x);
}

/// The free-bat exit speed: r = m (1/M + b^2 / I), q = (e - r) / (1 + r), q u + (1 + q) v_bat.
inline Real FreeBatExitSpeed(Real bat_mass, Real moi_centroid, Real b, Real m, Real u, Real v_bat,
                             Real e) {
  const Real r = m * (1 / bat_mass + b * b / moi_centroid);
  const Real q = (e - r) / (1 + r);
  return q * u + (1 + q) * v_bat;
}

/// The elastic contact of a ball of law F = k d^p on a rigid body (inverse effective mass c11,
/// ball included) struck at v0: d_max = ((p + 1) v0^2 / (2 c11 k))^(1/(p+1)) and
/// t_c = 2 (d_max / v0) B(1/(p+1), 1/2) / (p + 1) (energy conservation, then the time integral
/// of dd / sqrt(v0^2 - v0^2 (d/d_max)^(p+1))).
inline Real ElasticMaxCompression(Real c11, Real k, Real p, Real v0) {
  return std::pow((p + 1) * v0 * v0 / (2 * c11 * k), 1 / (p + 1));
}
inline Real ElasticContactTime(Real c11, Real k, Real p, Real v0) {
  const Real a = 1 / (p + 1);
  const Real beta = std::exp(std::lgamma(a) + std::lgamma(Real(0.5)) - std::lgamma(a + 0.5));
  return 2 * (ElasticMaxCompression(c11, k, p, v0) / v0) * beta / (p + 1);
}

/// Fundamental free-free bending frequency of a uniform Euler-Bernoulli beam, Hz:
/// (beta1 L)^2 / (2 pi L^2) sqrt(E I / (rho A)), beta1 L = 4.730040744862704 (the first root of
/// cos(x) cosh(x) = 1). For an annulus I / A = (r_o^2 + r_i^2) / 4.
inline Real UniformFreeFreeFundamentalHz(Real length, Real youngs, Real density, Real i_over_a) {
  const Real beta_l = 4.730040744862704026L;
  const Real pi = std::acos(Real(-1));
  return beta_l * beta_l / (2 * pi * length * length) * std::sqrt(youngs * i_over_a / density);
}

}  // namespace sweetspot::hard_cases
