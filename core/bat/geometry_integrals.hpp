// Internal: the exact integrals behind the mass properties, written once as
// templates on the scalar type (double for values; jet::Jet, core/numerics/jet.hpp, for exact
// first and second derivatives, with fixed-size storage, so no heap allocation).
// Included only by core's .cpp files.
//
// A profile segment [x_a, x_b] of length h has the outer radius
// r(tau) = r_m + dr * tau for tau in [-1, 1] (x = x_mid + tau * h / 2), with
// r_m = (r_a + r_b) / 2 and dr = (r_b - r_a) / 2. Every integrand is a
// polynomial in tau, integrated exactly; nothing divides by h, so a
// zero-length segment (a step) contributes exactly nothing and a 1e-12 m
// segment loses no accuracy. Moments are taken about the segment's midpoint
// (u = x - x_mid), which keeps every sum well conditioned:
//   solid:  A / pi = r^2 = r_m^2 + 2 r_m dr tau + dr^2 tau^2 (all even terms >= 0)
//   hollow: A / pi = r^2 - (r - t)^2 = t (2 r_m - t) + 2 t dr tau, written in this
//           form so the annulus never comes from subtracting two nearly equal squares.
#pragma once

#include <cstddef>
#include <vector>

#include "core/bat/bat.hpp"
#include "core/units.hpp"

namespace sweetspot::core::geometry {

/// Integrals of one segment per unit density.
template <typename T>
struct SegmentIntegrals {
  T volume;  ///< Integral of the cross-section area A over the segment, m^3.
  T first;   ///< Integral of A * u, u = x - x_mid, m^4.
  T second;  ///< Integral of A * u^2, m^5.
  T disk;    ///< Integral of pi (r_o^4 - r_i^4) / 4: the cross-sections' own moment, m^5.
};

/// Exact integrals of a segment of length h between outer radii r_a and r_b;
/// a hollow segment has the inner radius r - wall.
template <typename T>
SegmentIntegrals<T> IntegrateSegment(const T& h, const T& r_a, const T& r_b, const T& wall,
                                     bool hollow) {
  const T half = 0.5 * h;
  const T r_m = 0.5 * (r_a + r_b);
  const T dr = 0.5 * (r_b - r_a);
  // A / pi = a0 + a1 tau + a2 tau^2; the integral of the disk integrand
  // (r_o^4 - r_i^4) over tau in [-1, 1] is disk_tau.
  T a0, a1, a2, disk_tau;
  if (!hollow) {
    a0 = r_m * r_m;
    a1 = 2.0 * r_m * dr;
    a2 = dr * dr;
    // (r_m + dr tau)^4, even terms: r_m^4 + 6 r_m^2 dr^2 tau^2 + dr^4 tau^4.
    disk_tau = 2.0 * (a0 * a0) + 4.0 * (a0 * a2) + 0.4 * (a2 * a2);
  } else {
    const T inner_m = r_m - wall;
    a0 = wall * (r_m + inner_m);  // t (2 r_m - t)
    a1 = 2.0 * wall * dr;
    a2 = T(0.0);
    // r_o^4 - r_i^4 = (r_o^2 - r_i^2)(r_o^2 + r_i^2) = (b0 + b1 tau)(g0 + g1 tau + g2 tau^2)
    const T g0 = r_m * r_m + inner_m * inner_m;
    const T g1 = 2.0 * dr * (r_m + inner_m);
    const T g2 = 2.0 * dr * dr;
    disk_tau = 2.0 * (a0 * g0) + (2.0 / 3.0) * (a0 * g2 + a1 * g1);
  }
  SegmentIntegrals<T> out;
  out.volume = (kPi * half) * (2.0 * a0 + (2.0 / 3.0) * a2);
  out.first = (kPi * half * half) * ((2.0 / 3.0) * a1);
  out.second = (kPi * half * half * half) * ((2.0 / 3.0) * a0 + 0.4 * a2);
  out.disk = (0.25 * kPi * half) * disk_tau;
  return out;
}

/// Exact integrals of a hollow segment whose wall is linear from wall_a to wall_b (issue 35:
/// walls per knot). With the inner radius s = r - t, linear too (s_m = r_m - t_m,
/// ds = dr - dt): A / pi = r^2 - s^2 = t (r + s), a quadratic in tau written as a product (no
/// difference of nearly equal squares), and r^4 - s^4 = (r^2 - s^2)(r^2 + s^2), a quartic.
/// For wall_a = wall_b it equals IntegrateSegment's hollow case up to rounding (that one is
/// used then, so a uniform wall's numbers do not move).
template <typename T>
SegmentIntegrals<T> IntegrateTaperedWallSegment(const T& h, const T& r_a, const T& r_b,
                                                const T& wall_a, const T& wall_b) {
  const T half = 0.5 * h;
  const T r_m = 0.5 * (r_a + r_b);
  const T dr = 0.5 * (r_b - r_a);
  const T t_m = 0.5 * (wall_a + wall_b);
  const T dt = 0.5 * (wall_b - wall_a);
  const T s_m = r_m - t_m;
  const T ds = dr - dt;
  const T sum_m = r_m + s_m;
  const T sum_d = dr + ds;
  const T a0 = t_m * sum_m;
  const T a1 = t_m * sum_d + dt * sum_m;
  const T a2 = dt * sum_d;
  const T g0 = r_m * r_m + s_m * s_m;
  const T g1 = 2.0 * (r_m * dr + s_m * ds);
  const T g2 = dr * dr + ds * ds;
  const T disk_tau =
      2.0 * (a0 * g0) + (2.0 / 3.0) * (a0 * g2 + a1 * g1 + a2 * g0) + 0.4 * (a2 * g2);
  SegmentIntegrals<T> out;
  out.volume = (kPi * half) * (2.0 * a0 + (2.0 / 3.0) * a2);
  out.first = (kPi * half * half) * ((2.0 / 3.0) * a1);
  out.second = (kPi * half * half * half) * ((2.0 / 3.0) * a0 + 0.4 * a2);
  out.disk = (0.25 * kPi * half) * disk_tau;
  return out;
}

/// The integrals of a segment with walls wall_a, wall_b at its ends: IntegrateSegment when
/// they are equal (or the segment is solid), IntegrateTaperedWallSegment otherwise.
template <typename T>
SegmentIntegrals<T> IntegrateSegmentWalls(const T& h, const T& r_a, const T& r_b, const T& wall_a,
                                          const T& wall_b, bool hollow, bool walls_equal) {
  if (!hollow || walls_equal) return IntegrateSegment<T>(h, r_a, r_b, wall_a, hollow);
  return IntegrateTaperedWallSegment<T>(h, r_a, r_b, wall_a, wall_b);
}

/// Read-only view of a knot list as a profile of doubles, with each knot's wall (its own, or
/// the bat's `wall`).
class KnotListProfile {
 public:
  KnotListProfile(const std::vector<ProfileKnot>& knots, double wall)
      : knots_(knots), wall_(wall) {}
  std::size_t size() const { return knots_.size(); }
  double x(std::size_t i) const { return knots_[i].x_m; }
  double r(std::size_t i) const { return knots_[i].radius_m; }
  double wall(std::size_t i) const {
    return knots_[i].wall_thickness_m > 0.0 ? knots_[i].wall_thickness_m : wall_;
  }

 private:
  const std::vector<ProfileKnot>& knots_;
  double wall_;
};

/// Everything but the profile, in the scalar type T.
template <typename T>
struct BodyScalars {
  T density;  ///< Bat material, kg/m^3.
  T wall;     ///< Wall thickness, m (used only when hollow).
  bool hollow = false;
  bool has_fill = false;
  T fill_radius;   ///< m.
  T fill_depth;    ///< m.
  T fill_density;  ///< kg/m^3.

  /// Density the fill adds on top of the bat: the fill's minus what it
  /// replaces (the bat's material in a solid bat, nothing in a hollow one).
  T FillExcessDensity() const { return hollow ? fill_density : T(fill_density - density); }
};

/// Body scalars of a bat, in double.
inline BodyScalars<double> BodyOf(const Bat& bat) {
  BodyScalars<double> b;
  b.density = bat.material.density_kg_m3;
  b.wall = bat.wall_thickness_m;
  b.hollow = bat.IsHollow();
  b.has_fill = bat.fill.has_value();
  b.fill_radius = b.has_fill ? bat.fill->RadiusM() : 0.0;
  b.fill_depth = b.has_fill ? bat.fill->depth_m : 0.0;
  b.fill_density = b.has_fill ? bat.fill->material.density_kg_m3 : 0.0;
  return b;
}

/// Mass and first moment about the knob.
template <typename T>
struct MassMoment {
  T mass;         ///< kg.
  T moment;       ///< Integral of lambda(x) x dx, kg m.
  T bat_volume;   ///< Volume of the bat's material before the bore, m^3.
  T fill_volume;  ///< Volume of the bore, m^3.
};

/// Pass 1: mass and first moment about the knob of a profile (knots may
/// coincide; the profile's first knot is taken as x = 0's reference).
template <typename T, typename Profile>
MassMoment<T> ComputeMassMoment(const Profile& p, const BodyScalars<T>& b) {
  T volume(0.0), first(0.0);
  const std::size_t n = p.size();
  for (std::size_t i = 0; i + 1 < n; ++i) {
    const T xa = p.x(i);
    const T xb = p.x(i + 1);
    const T h = xb - xa;
    const T mid = 0.5 * (xa + xb);
    const double wa = p.wall(i), wb = p.wall(i + 1);
    const SegmentIntegrals<T> s =
        IntegrateSegmentWalls<T>(h, p.r(i), p.r(i + 1), T(wa), T(wb), b.hollow, wa == wb);
    volume += s.volume;
    first += mid * s.volume + s.first;
  }
  MassMoment<T> out;
  out.mass = b.density * volume;
  out.moment = b.density * first;
  out.bat_volume = volume;
  out.fill_volume = T(0.0);
  if (b.has_fill) {
    const T length = p.x(n - 1);
    out.fill_volume = kPi * b.fill_radius * b.fill_radius * b.fill_depth;
    const T excess = b.FillExcessDensity() * out.fill_volume;
    out.mass += excess;
    out.moment += excess * (length - 0.5 * b.fill_depth);
  }
  return out;
}

/// Pass 2: moment of inertia about the centroid c (value only): the slender
/// integral of lambda(x) (x - c)^2 plus, when rigid, the cross-sections' own
/// moments. Summing positive terms about c avoids I_knob - M c^2.
template <typename Profile>
double ComputeCentroidalMoment(const Profile& p, const BodyScalars<double>& b, double c,
                               bool rigid) {
  double second = 0.0;
  double disk = 0.0;
  const std::size_t n = p.size();
  for (std::size_t i = 0; i + 1 < n; ++i) {
    const double xa = p.x(i);
    const double xb = p.x(i + 1);
    const double d = 0.5 * (xa + xb) - c;
    const double wa = p.wall(i), wb = p.wall(i + 1);
    const SegmentIntegrals<double> s =
        IntegrateSegmentWalls<double>(xb - xa, p.r(i), p.r(i + 1), wa, wb, b.hollow, wa == wb);
    second += (d * d) * s.volume + 2.0 * d * s.first + s.second;
    disk += s.disk;
  }
  double moment = b.density * (rigid ? second + disk : second);
  if (b.has_fill) {
    const double length = p.x(n - 1);
    const double volume = kPi * b.fill_radius * b.fill_radius * b.fill_depth;
    const double e = length - 0.5 * b.fill_depth - c;
    double own = e * e + b.fill_depth * b.fill_depth / 12.0;
    if (rigid) own += 0.25 * b.fill_radius * b.fill_radius;
    moment += b.FillExcessDensity() * volume * own;
  }
  return moment;
}

}  // namespace sweetspot::core::geometry
