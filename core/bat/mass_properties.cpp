#include "core/bat/mass_properties.hpp"

#include <cmath>
#include <limits>

#include "core/bat/geometry_integrals.hpp"
#include "core/numerics/jet.hpp"
#include "core/numerics/limits.hpp"

namespace sweetspot::core {
namespace {

MassProperties NanProperties(InertiaModel model) {
  MassProperties out;
  out.inertia_model = model;
  out.volume_m3 = out.mass_kg = out.balance_point_m = kNaN;
  out.moi_knob_kg_m2 = out.moi_centroid_kg_m2 = kNaN;
  return out;
}

// +1 when the fill's material adds to the volume, -1 when the bore removes
// the bat's material, 0 when both or neither (see MassProperties::volume_m3).
double FillVolumeSign(const Bat& bat) {
  if (!bat.fill.has_value()) return 0.0;
  return (bat.fill->IsEmpty() ? 0.0 : 1.0) - (bat.IsHollow() ? 0.0 : 1.0);
}

// An end cap or knob as mass-property terms (bat.hpp): a uniform solid cylinder of mass m,
// length l and radius r whose centre is `centroid` from the knob.
struct PartTerm {
  double mass = 0.0;      // kg
  double centroid = 0.0;  // m from the knob
  double length = 0.0;    // m
  double radius = 0.0;    // m
  bool at_tip = false;    // the end cap (its centre moves with L)
};

// The bat's parts as terms into out[0..2); returns how many.
int PartTerms(const Bat& bat, PartTerm out[2]) {
  int n = 0;
  const double length = bat.LengthM();
  if (bat.end_cap.has_value()) {
    out[n++] = {bat.end_cap->mass_kg, length - 0.5 * bat.end_cap->length_m, bat.end_cap->length_m,
                bat.PartRadiusM(true), true};
  }
  if (bat.knob.has_value()) {
    out[n++] = {bat.knob->mass_kg, 0.5 * bat.knob->length_m, bat.knob->length_m,
                bat.PartRadiusM(false), false};
  }
  return n;
}

// A part's own moment about a diameter through its centre, kg m^2: m l^2 / 12, plus m r^2 / 4
// for the rigid body (the slender rod omits the cross-section's own moment, as for the profile).
double PartOwnMoment(const PartTerm& p, bool rigid) {
  return p.mass * (p.length * p.length / 12.0 + (rigid ? 0.25 * p.radius * p.radius : 0.0));
}

// Derivatives of one segment's integrals w.r.t. (x_a, x_b, r_a, r_b, wall).
using SegmentAd = jet::Jet<5, false>;
// Derivatives of the fill's terms w.r.t. (bore radius, depth, L, excess density).
using FillAd = jet::Jet<4, false>;

// Sums over the profile's segments of the volume and of Q1, Q2 about the centroid (below).
struct ProfileSums {
  double volume = 0.0;
  double q1 = 0.0;
  double q2 = 0.0;
};

// Adds every profile segment's derivatives (in its local variables x_a, x_b, r_a, r_b, wall)
// of the volume, mass, Q1 and Q2 about the centroid c into the design-parameter gradients;
// returns the sums of the values. Flattened: IntegrateSegment and every Jet operation are
// inlined here (GCC otherwise keeps IntegrateSegment<SegmentAd> a call that returns its four
// Jets through memory, about a sixth of the gradient's time).
[[gnu::flatten]] ProfileSums AddProfileGradients(const Bat& bat,
                                                 const geometry::BodyScalars<double>& body,
                                                 const DesignParameterLayout& lay, double c,
                                                 bool rigid, Eigen::VectorXd* g_volume,
                                                 Eigen::VectorXd* g_mass, Eigen::VectorXd* g_q1,
                                                 Eigen::VectorXd* g_q2) {
  const int k = static_cast<int>(bat.knots.size());
  const double rho = body.density;
  ProfileSums sums;
  const SegmentAd wall = SegmentAd::Variable(body.wall, 4);
  for (int i = 0; i + 1 < k; ++i) {
    const ProfileKnot& a = bat.knots[static_cast<std::size_t>(i)];
    const ProfileKnot& b = bat.knots[static_cast<std::size_t>(i) + 1];
    const SegmentAd xa = SegmentAd::Variable(a.x_m, 0), xb = SegmentAd::Variable(b.x_m, 1),
                    ra = SegmentAd::Variable(a.radius_m, 2),
                    rb = SegmentAd::Variable(b.radius_m, 3);
    const SegmentAd h = xb - xa;
    const SegmentAd d = 0.5 * (xa + xb) - c;
    // A knot's own wall is not a design parameter (a constant); a knot without one has the
    // bat's wall, the layout's wall_thickness_m.
    const bool own_a = a.wall_thickness_m > 0.0, own_b = b.wall_thickness_m > 0.0;
    const SegmentAd wall_a = own_a ? SegmentAd(a.wall_thickness_m) : wall;
    const SegmentAd wall_b = own_b ? SegmentAd(b.wall_thickness_m) : wall;
    const bool same = !own_a && !own_b;  // both the bat's wall: the uniform formula
    const geometry::SegmentIntegrals<SegmentAd> s =
        same ? geometry::IntegrateSegment<SegmentAd>(h, ra, rb, wall, body.hollow)
             : geometry::IntegrateSegmentWalls<SegmentAd>(h, ra, rb, wall_a, wall_b, body.hollow,
                                                          false);
    const SegmentAd q1 = d * s.volume + s.first;
    // d^2 V + 2 d F + S with two products: d (q1 + F) + S.
    SegmentAd q2 = d * (q1 + s.first) + s.second;
    if (rigid) q2 += s.disk;
    const int index[5] = {lay.KnotPosition(i), lay.KnotPosition(i + 1), lay.KnotRadius(i),
                          lay.KnotRadius(i + 1), lay.WallThickness()};
    for (int j = 0; j < 5; ++j) {
      const std::size_t jj = static_cast<std::size_t>(j);
      (*g_volume)[index[j]] += s.volume.g[jj];
      (*g_mass)[index[j]] += rho * s.volume.g[jj];
      (*g_q1)[index[j]] += rho * q1.g[jj];
      (*g_q2)[index[j]] += rho * q2.g[jj];
    }
    sums.volume += s.volume.v;
    sums.q1 += q1.v;
    sums.q2 += q2.v;
  }
  return sums;
}

}  // namespace

bool ValidatePivotFromKnob(double pivot_from_knob_m, Refusal* refusal) {
  return CheckInRange(refusal, "pivot_from_knob_m", pivot_from_knob_m, -kMaxPivotFromKnobM,
                      kMaxPivotFromKnobM);
}

double MassProperties::MoiAboutKgM2(double pivot_from_knob_m) const {
  const double d = pivot_from_knob_m - balance_point_m;
  return moi_centroid_kg_m2 + mass_kg * (d * d);
}

namespace {

// The probe of MassPropertiesComputationsOnThisThread: per thread, so no state is shared.
thread_local long long computations_on_this_thread = 0;

// The mass, balance point and volume of a valid bat (the same under both inertia models),
// its moments left at 0.
MassProperties MassWithoutMoments(const Bat& bat, const geometry::KnotListProfile& profile,
                                  const geometry::BodyScalars<double>& body) {
  const geometry::MassMoment<double> mm = geometry::ComputeMassMoment<double>(profile, body);
  MassProperties out;
  double mass = mm.mass;
  double moment = mm.moment;
  PartTerm parts[2];
  const int num_parts = PartTerms(bat, parts);
  for (int i = 0; i < num_parts; ++i) {
    mass += parts[i].mass;
    moment += parts[i].mass * parts[i].centroid;
  }
  double volume = mm.bat_volume + FillVolumeSign(bat) * mm.fill_volume;
  // A two-piece bat (bat.hpp Handle): over [0, joint] the handle's side replaces the bat's
  // (their difference first: 0 exactly for a handle of the bat's own material and wall).
  if (bat.handle.has_value()) {
    geometry::MassMoment<double> s[2];
    for (int i = 0; i < 2; ++i) {
      const Bat side = bat.HandleRegion(/*handle_side=*/i == 0);
      s[i] = geometry::ComputeMassMoment<double>(
          geometry::KnotListProfile(side.knots, side.wall_thickness_m), geometry::BodyOf(side));
    }
    mass += s[0].mass - s[1].mass;
    moment += s[0].moment - s[1].moment;
    volume += s[0].bat_volume - s[1].bat_volume;
  }
  out.mass_kg = mass;
  out.balance_point_m = moment / mass;
  out.volume_m3 = volume;
  return out;
}

// `base` with its moments under `model`.
MassProperties WithMoments(const Bat& bat, MassProperties out, InertiaModel model,
                           const geometry::KnotListProfile& profile,
                           const geometry::BodyScalars<double>& body) {
  out.inertia_model = model;
  const bool rigid = model == InertiaModel::kRigidBody;
  out.moi_centroid_kg_m2 =
      geometry::ComputeCentroidalMoment(profile, body, out.balance_point_m, rigid);
  PartTerm parts[2];
  const int num_parts = PartTerms(bat, parts);
  for (int i = 0; i < num_parts; ++i) {
    const double d = parts[i].centroid - out.balance_point_m;
    out.moi_centroid_kg_m2 += parts[i].mass * (d * d) + PartOwnMoment(parts[i], rigid);
  }
  if (bat.handle.has_value()) {  // as in MassWithoutMoments
    double side_moment[2];
    for (int i = 0; i < 2; ++i) {
      const Bat side = bat.HandleRegion(/*handle_side=*/i == 0);
      side_moment[i] = geometry::ComputeCentroidalMoment(
          geometry::KnotListProfile(side.knots, side.wall_thickness_m), geometry::BodyOf(side),
          out.balance_point_m, rigid);
    }
    out.moi_centroid_kg_m2 += side_moment[0] - side_moment[1];
  }
  out.moi_knob_kg_m2 = out.MoiAboutKgM2(0.0);
  return out;
}

}  // namespace

long long MassPropertiesComputationsOnThisThread() { return computations_on_this_thread; }

MassProperties ComputeMassProperties(const Bat& bat, InertiaModel model) {
  if (!bat.Validate(nullptr)) return NanProperties(model);
  return ComputeMassPropertiesOfValidBat(bat, model);
}

MassProperties ComputeMassPropertiesOfValidBat(const Bat& bat, InertiaModel model) {
  ++computations_on_this_thread;
  const geometry::KnotListProfile profile(bat.knots, bat.wall_thickness_m);
  const geometry::BodyScalars<double> body = geometry::BodyOf(bat);
  return WithMoments(bat, MassWithoutMoments(bat, profile, body), model, profile, body);
}

MassPropertiesOfBothModels ComputeMassPropertiesOfBothModels(const Bat& bat) {
  if (!bat.Validate(nullptr)) {
    return {NanProperties(InertiaModel::kRigidBody), NanProperties(InertiaModel::kSlenderRod)};
  }
  ++computations_on_this_thread;
  const geometry::KnotListProfile profile(bat.knots, bat.wall_thickness_m);
  const geometry::BodyScalars<double> body = geometry::BodyOf(bat);
  const MassProperties mass = MassWithoutMoments(bat, profile, body);
  return {WithMoments(bat, mass, InertiaModel::kRigidBody, profile, body),
          WithMoments(bat, mass, InertiaModel::kSlenderRod, profile, body)};
}

std::string DesignParameterLayout::Name(int index) const {
  const int k = num_knots;
  if (index < 0 || index >= Size()) return "";
  if (index < k) return "knots[" + std::to_string(index) + "].radius_m";
  if (index < 2 * k) return "knots[" + std::to_string(index - k) + "].x_m";
  switch (index - 2 * k) {
    case 0:
      return "density_kg_m3";
    case 1:
      return "wall_thickness_m";
    case 2:
      return "fill.diameter_m";
    case 3:
      return "fill.depth_m";
    default:
      return "fill.density_kg_m3";
  }
}

Eigen::VectorXd DesignParameters(const Bat& bat) {
  DesignParameterLayout layout{static_cast<int>(bat.knots.size())};
  Eigen::VectorXd p = Eigen::VectorXd::Zero(layout.Size());
  for (int i = 0; i < layout.num_knots; ++i) {
    p[layout.KnotRadius(i)] = bat.knots[static_cast<std::size_t>(i)].radius_m;
    p[layout.KnotPosition(i)] = bat.knots[static_cast<std::size_t>(i)].x_m;
  }
  p[layout.Density()] = bat.material.density_kg_m3;
  p[layout.WallThickness()] = bat.wall_thickness_m;
  if (bat.fill.has_value()) {
    p[layout.FillDiameter()] = bat.fill->diameter_m;
    p[layout.FillDepth()] = bat.fill->depth_m;
    p[layout.FillDensity()] = bat.fill->material.density_kg_m3;
  }
  return p;
}

Bat WithDesignParameters(const Bat& bat, const Eigen::VectorXd& parameters) {
  DesignParameterLayout layout{static_cast<int>(bat.knots.size())};
  if (parameters.size() != layout.Size()) return bat;
  Bat out = bat;
  for (int i = 0; i < layout.num_knots; ++i) {
    out.knots[static_cast<std::size_t>(i)].radius_m = parameters[layout.KnotRadius(i)];
    out.knots[static_cast<std::size_t>(i)].x_m = parameters[layout.KnotPosition(i)];
  }
  out.material.density_kg_m3 = parameters[layout.Density()];
  out.wall_thickness_m = parameters[layout.WallThickness()];
  if (out.fill.has_value()) {
    out.fill->diameter_m = parameters[layout.FillDiameter()];
    out.fill->depth_m = parameters[layout.FillDepth()];
    out.fill->material.density_kg_m3 = parameters[layout.FillDensity()];
  }
  return out;
}

Eigen::VectorXd MassPropertiesWithGradient::MoiAboutGradient(double pivot_from_knob_m) const {
  const double d = pivot_from_knob_m - properties.balance_point_m;
  return moi_centroid_gradient + (d * d) * mass_gradient -
         (2.0 * properties.mass_kg * d) * balance_point_gradient;
}

// The gradient follows from three sums taken about the (fixed) centroid C:
//   G0 = sum lambda,  Q1 = sum lambda (x - C),  Q2 = sum lambda (x - C)^2 (+ disk terms).
// Since Q1 = 0 defines C, dC = dQ1 / M and dI_cm = dQ2 with C held fixed
// (dQ2/dC = -2 Q1 = 0): the derivatives are taken term by term about C, so
// they are as well conditioned as the values (no dS1 - C dM cancellation).
MassPropertiesWithGradient ComputeMassPropertiesWithGradient(const Bat& bat, InertiaModel model) {
  MassPropertiesWithGradient out;
  const int k = static_cast<int>(bat.knots.size());
  out.layout.num_knots = k;
  const int n = out.layout.Size();
  out.properties = ComputeMassProperties(bat, model);
  if (!std::isfinite(out.properties.mass_kg) || bat.handle.has_value()) {
    out.volume_gradient = out.mass_gradient = out.balance_point_gradient = out.moi_knob_gradient =
        out.moi_centroid_gradient = Eigen::VectorXd::Constant(n, kNaN);
    return out;
  }
  const bool rigid = model == InertiaModel::kRigidBody;
  const geometry::BodyScalars<double> body = geometry::BodyOf(bat);
  const double c = out.properties.balance_point_m;
  const double mass = out.properties.mass_kg;
  const DesignParameterLayout& lay = out.layout;

  Eigen::VectorXd g_volume = Eigen::VectorXd::Zero(n);  // geometric volume of the profile
  Eigen::VectorXd g_mass = Eigen::VectorXd::Zero(n);
  Eigen::VectorXd g_q1 = Eigen::VectorXd::Zero(n);
  Eigen::VectorXd g_q2 = Eigen::VectorXd::Zero(n);  // includes the disk terms when rigid

  const ProfileSums sums =
      AddProfileGradients(bat, body, lay, c, rigid, &g_volume, &g_mass, &g_q1, &g_q2);
  g_mass[lay.Density()] += sums.volume;
  g_q1[lay.Density()] += sums.q1;
  g_q2[lay.Density()] += sums.q2;

  if (body.has_fill) {
    const double excess_value = body.FillExcessDensity();
    const FillAd radius = FillAd::Variable(body.fill_radius, 0),
                 depth = FillAd::Variable(body.fill_depth, 1),
                 length = FillAd::Variable(bat.LengthM(), 2),
                 excess = FillAd::Variable(excess_value, 3);
    const FillAd volume = kPi * radius * radius * depth;
    const FillAd e = length - 0.5 * depth - c;
    FillAd own = e * e + depth * depth / 12.0;
    if (rigid) own += 0.25 * radius * radius;
    const FillAd f_mass = excess * volume;
    const FillAd f_q1 = f_mass * e;
    const FillAd f_q2 = f_mass * own;
    const double sign = FillVolumeSign(bat);
    // Chain rule: radius = diameter / 2; L = knots[K-1].x_m; the excess density
    // is fill density minus (solid bats only) the bat's density.
    const int index[3] = {lay.FillDiameter(), lay.FillDepth(), lay.KnotPosition(k - 1)};
    const double scale[3] = {0.5, 1.0, 1.0};
    for (int j = 0; j < 3; ++j) {
      g_volume[index[j]] += sign * scale[j] * volume.g[static_cast<std::size_t>(j)];
      g_mass[index[j]] += scale[j] * f_mass.g[static_cast<std::size_t>(j)];
      g_q1[index[j]] += scale[j] * f_q1.g[static_cast<std::size_t>(j)];
      g_q2[index[j]] += scale[j] * f_q2.g[static_cast<std::size_t>(j)];
    }
    const double d_excess_d_density = body.hollow ? 0.0 : -1.0;
    g_mass[lay.FillDensity()] += f_mass.g[3];
    g_q1[lay.FillDensity()] += f_q1.g[3];
    g_q2[lay.FillDensity()] += f_q2.g[3];
    g_mass[lay.Density()] += d_excess_d_density * f_mass.g[3];
    g_q1[lay.Density()] += d_excess_d_density * f_q1.g[3];
    g_q2[lay.Density()] += d_excess_d_density * f_q2.g[3];
  }

  // The end cap and knob: their masses are not design parameters; the end cap's centre,
  // L - l / 2, moves with L (the last knot's x), and a rigid body's m r^2 / 4 with the radius
  // at the part's end (r = r_end - wall for a hollow bat).
  PartTerm parts[2];
  const int num_parts = PartTerms(bat, parts);
  for (int i = 0; i < num_parts; ++i) {
    const PartTerm& p = parts[i];
    if (p.at_tip) {
      g_q1[lay.KnotPosition(k - 1)] += p.mass;
      g_q2[lay.KnotPosition(k - 1)] += 2.0 * p.mass * (p.centroid - c);
    }
    if (rigid) {
      const double d_own_d_r = 0.5 * p.mass * p.radius;
      g_q2[p.at_tip ? lay.KnotRadius(k - 1) : lay.KnotRadius(0)] += d_own_d_r;
      const ProfileKnot& end = p.at_tip ? bat.knots.back() : bat.knots.front();
      if (body.hollow && end.wall_thickness_m <= 0.0) g_q2[lay.WallThickness()] -= d_own_d_r;
    }
  }

  out.volume_gradient = std::move(g_volume);
  out.balance_point_gradient = g_q1 / mass;
  out.moi_centroid_gradient = g_q2;
  out.moi_knob_gradient = g_q2 + (c * c) * g_mass + (2.0 * mass * c) * out.balance_point_gradient;
  out.mass_gradient = std::move(g_mass);
  return out;
}

ImperialProperties ToImperial(const MassProperties& properties, double length_m) {
  ImperialProperties out;
  out.length_in = MetresToInches(length_m);
  out.weight_oz = KilogramsToOunces(properties.mass_kg);
  out.drop = BatDrop(out.length_in, out.weight_oz);
  out.balance_point_in = MetresToInches(properties.balance_point_m);
  out.moi_knob_oz_in2 = KgM2ToOzIn2(properties.moi_knob_kg_m2);
  out.moi_six_inch_oz_in2 = KgM2ToOzIn2(properties.MoiSixInchKgM2());
  out.moi_centroid_oz_in2 = KgM2ToOzIn2(properties.moi_centroid_kg_m2);
  return out;
}

}  // namespace sweetspot::core
