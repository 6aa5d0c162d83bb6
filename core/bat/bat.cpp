#include "core/bat/bat.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "core/geometry_format.hpp"
#include "core/refusal.hpp"

namespace sweetspot::core {
namespace {

// Checks a material and prefixes its refusal's field with `prefix` ("material.").
bool CheckMaterial(const Material& m, std::string_view prefix, Refusal* out) {
  if (out == nullptr) return m.Validate(nullptr);
  Refusal inner;
  if (m.Validate(&inner)) return true;
  return Refuse(out, Prefixed(prefix, std::move(inner)));
}

// Material::ValidateSize with the refusal's field prefixed by `prefix`.
bool CheckMaterialSize(const Material& m, std::string_view prefix, Refusal* out) {
  if (out == nullptr) return m.ValidateSize(nullptr);
  Refusal inner;
  if (m.ValidateSize(&inner)) return true;
  return Refuse(out, Prefixed(prefix, std::move(inner)));
}

// Outer radius of a valid knot list at x in [x_0, x_last].
double Interpolate(const std::vector<ProfileKnot>& knots, double x) {
  const auto it = std::upper_bound(knots.begin(), knots.end(), x,
                                   [](double v, const ProfileKnot& k) { return v < k.x_m; });
  if (it == knots.begin()) return knots.front().radius_m;
  if (it == knots.end()) return knots.back().radius_m;
  const ProfileKnot& b = *it;
  const ProfileKnot& a = *(it - 1);
  const double t = (x - a.x_m) / (b.x_m - a.x_m);  // in [0, 1): bounded even for a step
  return a.radius_m + (b.radius_m - a.radius_m) * t;
}

// Every check of ThreeSegmentShape::Validate at once: finite, L, r1, r2 > 0 and
// 0 <= x1 <= x2 <= L.
bool ShapePassesEveryCheck(const ThreeSegmentShape& s) {
  return std::isfinite(s.length_m) && std::isfinite(s.handle_radius_m) &&
         std::isfinite(s.barrel_radius_m) && std::isfinite(s.taper_start_m) &&
         std::isfinite(s.taper_end_m) && s.length_m > 0.0 && s.handle_radius_m > 0.0 &&
         s.barrel_radius_m > 0.0 && s.taper_start_m >= 0.0 && s.taper_start_m <= s.taper_end_m &&
         s.taper_end_m <= s.length_m;
}

}  // namespace

bool ThreeSegmentShape::Validate(Refusal* why) const {
  // Every check below at once (a sweep's shapes pass them all); only a shape that fails one
  // is checked in order, for its refusal.
  if (ShapePassesEveryCheck(*this)) return true;
  const struct {
    const char* name;
    double value;
  } fields[] = {{"length_m", length_m},
                {"handle_radius_m", handle_radius_m},
                {"barrel_radius_m", barrel_radius_m},
                {"taper_start_m", taper_start_m},
                {"taper_end_m", taper_end_m}};
  for (const auto& f : fields) {
    if (!std::isfinite(f.value)) return Refuse(why, f.name, f.value, "must be finite");
  }
  if (!(length_m > 0.0)) return Refuse(why, "length_m", length_m, "must be positive");
  if (!(handle_radius_m > 0.0)) {
    return Refuse(why, "handle_radius_m", handle_radius_m, "must be positive");
  }
  if (!(barrel_radius_m > 0.0)) {
    return Refuse(why, "barrel_radius_m", barrel_radius_m, "must be positive");
  }
  if (taper_start_m < 0.0) {
    return Refuse(why, "taper_start_m", taper_start_m, "must be non-negative");
  }
  if (taper_start_m > taper_end_m) {
    return Refuse(why, "taper_start_m", taper_start_m,
                  "must not exceed taper_end_m = " + FormatNumber(taper_end_m));
  }
  if (taper_end_m > length_m) {
    return Refuse(why, "taper_end_m", taper_end_m,
                  "must not exceed length_m = " + FormatNumber(length_m));
  }
  return true;
}

bool ThreeSegmentShape::ValidateSize(Refusal* why) const {
  // Validate's checks and the caps below at once (a sweep's shapes pass them all).
  if (ShapePassesEveryCheck(*this) && length_m <= kMaxBatLengthM &&
      handle_radius_m <= kMaxBatRadiusM && barrel_radius_m <= kMaxBatRadiusM) {
    return true;
  }
  // Validate holds x1 <= x2 <= L: the positions are then within the length's cap too.
  if (!Validate(why)) return false;
  // Validate holds L, r1, r2 finite and positive: within the caps, the checks below all pass
  // (a sweep's designs, one shape after another, take this way).
  if (length_m <= kMaxBatLengthM && handle_radius_m <= kMaxBatRadiusM &&
      barrel_radius_m <= kMaxBatRadiusM) {
    return true;
  }
  return CheckInRange(why, "length_m", length_m, 0.0, kMaxBatLengthM, /*lo_open=*/true) &&
         CheckInRange(why, "handle_radius_m", handle_radius_m, 0.0, kMaxBatRadiusM, true) &&
         CheckInRange(why, "barrel_radius_m", barrel_radius_m, 0.0, kMaxBatRadiusM, true);
}

std::vector<ProfileKnot> ThreeSegmentShape::Knots() const {
  std::vector<ProfileKnot> out;
  out.reserve(4);
  KnotsInto(&out);
  return out;
}

void ThreeSegmentShape::KnotsInto(std::vector<ProfileKnot>* knots) const {
  std::vector<ProfileKnot>& out = *knots;
  out.clear();
  const double length = length_m;
  const double r1 = handle_radius_m;
  const double r2 = barrel_radius_m;
  double x1 = taper_start_m;
  double x2 = taper_end_m;
  if (x1 == x2) {
    if (x1 <= 0.0) {  // all barrel
      out.assign({{0.0, r2}, {length, r2}});
      return;
    }
    if (x1 >= length) {  // all handle
      out.assign({{0.0, r1}, {length, r1}});
      return;
    }
    if (r1 == r2) {
      out.assign({{0.0, r1}, {x1, r1}, {length, r1}});
      return;
    }
    // A zero-length taper is a step: two knots a tiny distance apart.
    const double half_width = 0.5 * kStepWidth * length;
    x1 = std::max(x1 - half_width, 0.0);
    x2 = std::min(x2 + half_width, length);
  }
  out.push_back({0.0, r1});
  if (x1 > 0.0) out.push_back({x1, r1});
  out.push_back({x2, r2});
  if (x2 < length) out.push_back({length, r2});
}

bool Bat::Validate(Refusal* why) const { return ValidateChecks(why, /*materials=*/true); }

bool Bat::ValidateGeometry(Refusal* why) const { return ValidateChecks(why, /*materials=*/false); }

bool Bat::ValidateChecks(Refusal* why, bool materials) const {
  const std::size_t n = knots.size();
  // The knots' checks below in one pass (a sweep's designs pass them all), with the smallest
  // radius; only knots that fail one are checked again in order, for the refusal.
  // Each knot: x finite and above the previous one's (the first's is 0), radius finite and
  // positive; as comparisons combined without branches (a NaN fails them all).
  constexpr double kInf = std::numeric_limits<double>::infinity();
  bool knots_pass = n >= 2 && knots[0].x_m == 0.0;
  double min_radius = kInf;  // as MinRadiusM()
  double previous_x = -kInf;
  for (const ProfileKnot& k : knots) {
    const double x = k.x_m;
    const double r = k.radius_m;
    knots_pass &= (x > previous_x) & (x < kInf) & (r > 0.0) & (r < kInf);
    previous_x = x;
    min_radius = std::min(min_radius, r);
  }
  if (!knots_pass && !ValidateKnotOrder(why)) return false;
  return ValidateBody(why, materials, min_radius);
}

bool Bat::ValidateGeometryOfShapeKnots(Refusal* why) const {
  if (knots.size() < 2) return ValidateGeometry(why);
  double min_radius = knots.front().radius_m;  // as MinRadiusM(): the radii are finite
  for (std::size_t i = 1; i < knots.size(); ++i) {
    if (!(knots[i].x_m > knots[i - 1].x_m)) return ValidateGeometry(why);  // refused there
    min_radius = std::min(min_radius, knots[i].radius_m);
  }
  // No fill, no parts, no knot walls and a wall in [0, min_radius) (so finite): ValidateBody's
  // checks all pass.
  if (!fill.has_value() && !end_cap.has_value() && !knob.has_value() && !handle.has_value() &&
      !HasKnotWalls() && wall_thickness_m >= 0.0 && wall_thickness_m < min_radius) {
    return true;
  }
  return ValidateBody(why, /*materials=*/false, min_radius);
}

bool Bat::ValidateKnotOrder(Refusal* why) const {
  const std::size_t n = knots.size();
  if (n < 2) {
    return Refuse(why, "knots.size()", static_cast<double>(n), "must be at least 2");
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(knots[i].x_m)) {
      return why == nullptr
                 ? false
                 : Refuse(why, IndexedField("knots", i, "x_m"), knots[i].x_m, "must be finite");
    }
    if (!std::isfinite(knots[i].radius_m)) {
      return why == nullptr ? false
                            : Refuse(why, IndexedField("knots", i, "radius_m"), knots[i].radius_m,
                                     "must be finite");
    }
  }
  if (knots[0].x_m != 0.0) {
    return Refuse(why, "knots[0].x_m", knots[0].x_m,
                  "must be 0 (positions are measured from the knob)");
  }
  for (std::size_t i = 1; i < n; ++i) {
    if (!(knots[i].x_m > knots[i - 1].x_m)) {
      return why == nullptr ? false
                            : Refuse(why, IndexedField("knots", i, "x_m"), knots[i].x_m,
                                     "must be greater than " + IndexedField("knots", i - 1, "x_m") +
                                         " = " + FormatNumber(knots[i - 1].x_m));
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (!(knots[i].radius_m > 0.0)) {
      return why == nullptr ? false
                            : Refuse(why, IndexedField("knots", i, "radius_m"), knots[i].radius_m,
                                     "must be positive");
    }
  }
  return true;
}

bool Bat::ValidateBody(Refusal* why, bool materials, double min_radius) const {
  if (materials && !CheckMaterial(material, "material.", why)) return false;

  if (!std::isfinite(wall_thickness_m)) {
    return Refuse(why, "wall_thickness_m", wall_thickness_m, "must be finite");
  }
  if (wall_thickness_m < 0.0) {
    return Refuse(why, "wall_thickness_m", wall_thickness_m, "must be non-negative (0 = solid)");
  }
  if (wall_thickness_m >= min_radius) {
    return Refuse(why, "wall_thickness_m", wall_thickness_m,
                  "must be less than the smallest outer radius " + FormatNumber(min_radius));
  }
  for (std::size_t i = 0; i < knots.size(); ++i) {
    const double t = knots[i].wall_thickness_m;
    if (t == 0.0) continue;
    if (why == nullptr) {
      if (!(std::isfinite(t) && t > 0.0 && IsHollow() && t < knots[i].radius_m)) return false;
      continue;
    }
    const std::string field = IndexedField("knots", i, "wall_thickness_m");
    if (!std::isfinite(t)) return Refuse(why, field, t, "must be finite");
    if (t < 0.0) return Refuse(why, field, t, "must be non-negative (0 = the bat's wall)");
    if (!IsHollow()) {
      return Refuse(why, field, t, "needs a hollow bat (wall_thickness_m > 0, the default wall)");
    }
    if (t >= knots[i].radius_m) {
      return Refuse(why, field, t,
                    "must be less than the knot's radius " + FormatNumber(knots[i].radius_m));
    }
  }

  if (fill.has_value()) {
    const Fill& f = *fill;
    if (!std::isfinite(f.material.density_kg_m3)) {
      return Refuse(why, "fill.material.density_kg_m3", f.material.density_kg_m3, "must be finite");
    }
    if (f.material.density_kg_m3 < 0.0) {
      return Refuse(why, "fill.material.density_kg_m3", f.material.density_kg_m3,
                    "must be non-negative (0 = empty bore)");
    }
    if (materials && !f.IsEmpty() && !CheckMaterial(f.material, "fill.material.", why)) {
      return false;
    }
    if (!std::isfinite(f.diameter_m)) {
      return Refuse(why, "fill.diameter_m", f.diameter_m, "must be finite");
    }
    if (f.diameter_m < 0.0)
      return Refuse(why, "fill.diameter_m", f.diameter_m, "must be non-negative");
    if (!std::isfinite(f.depth_m)) return Refuse(why, "fill.depth_m", f.depth_m, "must be finite");
    if (f.depth_m < 0.0) return Refuse(why, "fill.depth_m", f.depth_m, "must be non-negative");
    const double length = LengthM();
    if (f.depth_m > length) {
      return Refuse(why, "fill.depth_m", f.depth_m,
                    "must not exceed the bat's length " + FormatNumber(length));
    }
    // The material around the bore is thinnest at a knot inside the fill's
    // range or at the bore's bottom (the profile is piecewise linear).
    const double start = length - f.depth_m;
    double worst_x = start;
    double worst_r = Interpolate(knots, start);
    for (const ProfileKnot& k : knots) {
      if (k.x_m > start && k.radius_m < worst_r) {
        worst_r = k.radius_m;
        worst_x = k.x_m;
      }
    }
    // The wall at that point (0 for a solid bat; linear between knots' own walls, so the
    // inner radius is linear too and thinnest at the same places).
    double around = worst_r - (IsHollow() ? WallAtM(worst_x) : 0.0);
    if (HasKnotWalls() && IsHollow()) {  // the inner radius's own minimum over the range
      around = InnerRadiusAtM(start);
      worst_x = start;
      for (std::size_t i = 0; i < knots.size(); ++i) {
        if (knots[i].x_m > start && knots[i].radius_m - KnotWallM(i) < around) {
          around = knots[i].radius_m - KnotWallM(i);
          worst_x = knots[i].x_m;
        }
      }
    }
    if (!(f.RadiusM() < around)) {
      return why == nullptr
                 ? false
                 : Refuse(why, "fill.diameter_m", f.diameter_m,
                          "the bore radius " + FormatNumber(f.RadiusM()) +
                              " must be less than the " + (IsHollow() ? "inner" : "outer") +
                              " radius " + FormatNumber(around) +
                              " at x_m = " + FormatNumber(worst_x) + " (over the fill's depth)");
    }
  }
  return ValidatePart(end_cap, "end_cap.", why) && ValidatePart(knob, "knob.", why) &&
         ValidateHandle(why, materials);
}

bool Bat::ValidateHandle(Refusal* why, bool materials) const {
  if (!handle.has_value()) return true;
  const Handle& h = *handle;
  if (materials && !CheckMaterial(h.material, "handle.material.", why)) return false;
  const double length = LengthM();
  if (!(h.joint_from_knob_m > 0.0 && h.joint_from_knob_m < length)) {
    return Refuse(why, "handle.joint_from_knob_m", h.joint_from_knob_m,
                  "must be in (0, " + FormatNumber(length) + ") (inside the bat)");
  }
  if (fill.has_value() && fill->depth_m > length - h.joint_from_knob_m) {
    return Refuse(why, "handle.joint_from_knob_m", h.joint_from_knob_m,
                  "the fill (depth " + FormatNumber(fill->depth_m) +
                      ") must not reach past the joint into the handle");
  }
  if (h.wall_thickness_m.has_value()) {
    const double t = *h.wall_thickness_m;
    if (!std::isfinite(t)) return Refuse(why, "handle.wall_thickness_m", t, "must be finite");
    if (t < 0.0)
      return Refuse(why, "handle.wall_thickness_m", t, "must be non-negative (0 = solid)");
    double r_min = Interpolate(knots, h.joint_from_knob_m);
    for (const ProfileKnot& k : knots) {
      if (k.x_m < h.joint_from_knob_m) r_min = std::min(r_min, k.radius_m);
    }
    if (t >= r_min) {
      return Refuse(why, "handle.wall_thickness_m", t,
                    "must be less than the handle's smallest outer radius " + FormatNumber(r_min));
    }
  }
  return true;
}

Bat Bat::HandleRegion(bool handle_side) const {
  Bat out;
  const double joint = handle->joint_from_knob_m;
  const bool knot_walls = IsHollow() && HasKnotWalls();
  for (const ProfileKnot& k : knots) {
    if (!(k.x_m < joint)) break;
    out.knots.push_back(k);
  }
  ProfileKnot end;
  end.x_m = joint;
  end.radius_m = Interpolate(knots, joint);
  end.wall_thickness_m = knot_walls ? WallAtM(joint) : 0.0;
  out.knots.push_back(end);
  out.material = material;
  out.wall_thickness_m = wall_thickness_m;
  if (handle_side) {
    out.material = handle->material;
    if (handle->wall_thickness_m.has_value()) {
      out.wall_thickness_m = *handle->wall_thickness_m;
      for (ProfileKnot& k : out.knots) k.wall_thickness_m = 0.0;
    }
  }
  return out;
}

bool Bat::ValidatePart(const std::optional<BatPart>& part, std::string_view prefix,
                       Refusal* why) const {
  if (!part.has_value()) return true;
  const std::string p(prefix);
  if (!std::isfinite(part->mass_kg))
    return Refuse(why, p + "mass_kg", part->mass_kg, "must be finite");
  if (!(part->mass_kg > 0.0)) return Refuse(why, p + "mass_kg", part->mass_kg, "must be positive");
  return CheckInRange(why, p + "length_m", part->length_m, 0.0, LengthM(), /*lo_open=*/true);
}

bool Bat::ValidateSize(Refusal* why) const { return Validate(why) && ValidateCaps(why); }

bool Bat::ValidateKnotCaps(Refusal* why) const {
  for (std::size_t i = 0; i < knots.size(); ++i) {
    if (knots[i].x_m > kMaxBatLengthM) {
      return why == nullptr ? false
                            : CheckInRange(why, IndexedField("knots", i, "x_m"), knots[i].x_m, 0.0,
                                           kMaxBatLengthM);
    }
    if (knots[i].radius_m > kMaxBatRadiusM) {
      return why == nullptr
                 ? false
                 : CheckInRange(why, IndexedField("knots", i, "radius_m"), knots[i].radius_m, 0.0,
                                kMaxBatRadiusM, /*lo_open=*/true);
    }
  }
  return true;
}

bool Bat::ValidateCaps(Refusal* why) const {
  if (!ValidateKnotCaps(why)) return false;
  // Validate holds the wall below the smallest radius and the fill no deeper than the bat: the
  // caps on the radii and the length hold them too.
  if (!CheckMaterialSize(material, "material.", why)) return false;
  if (fill.has_value()) {
    if (!fill->IsEmpty() && !CheckMaterialSize(fill->material, "fill.material.", why)) return false;
    if (!CheckInRange(why, "fill.diameter_m", fill->diameter_m, 0.0, kMaxFillDiameterM)) {
      return false;
    }
  }
  if (end_cap.has_value() &&
      !CheckInRange(why, "end_cap.mass_kg", end_cap->mass_kg, 0.0, kMaxBatPartMassKg, true)) {
    return false;
  }
  if (knob.has_value() &&
      !CheckInRange(why, "knob.mass_kg", knob->mass_kg, 0.0, kMaxBatPartMassKg, true)) {
    return false;
  }
  if (handle.has_value() && !CheckMaterialSize(handle->material, "handle.material.", why)) {
    return false;
  }
  return true;
}

double Bat::LengthM() const { return knots.empty() ? 0.0 : knots.back().x_m; }

double Bat::RadiusAtM(double x_m) const {
  if (knots.empty() || !(x_m >= knots.front().x_m && x_m <= knots.back().x_m)) return 0.0;
  return Interpolate(knots, x_m);
}

bool Bat::HasKnotWalls() const {
  for (const ProfileKnot& k : knots) {
    if (k.wall_thickness_m != 0.0) return true;
  }
  return false;
}

double Bat::WallAtM(double x_m) const {
  if (!IsHollow() || knots.empty() || !(x_m >= knots.front().x_m && x_m <= knots.back().x_m)) {
    return 0.0;
  }
  if (!HasKnotWalls()) return wall_thickness_m;
  const auto it = std::upper_bound(knots.begin(), knots.end(), x_m,
                                   [](double v, const ProfileKnot& k) { return v < k.x_m; });
  if (it == knots.begin()) return KnotWallM(0);
  if (it == knots.end()) return KnotWallM(knots.size() - 1);
  const std::size_t b = static_cast<std::size_t>(it - knots.begin());
  const double t = (x_m - knots[b - 1].x_m) / (knots[b].x_m - knots[b - 1].x_m);
  return KnotWallM(b - 1) + (KnotWallM(b) - KnotWallM(b - 1)) * t;
}

double Bat::InnerRadiusAtM(double x_m) const {
  if (!IsHollow()) return 0.0;
  return std::max(RadiusAtM(x_m) - WallAtM(x_m), 0.0);
}

double Bat::MinRadiusM() const {
  if (knots.empty()) return 0.0;
  double r = std::numeric_limits<double>::infinity();
  for (const ProfileKnot& k : knots) r = std::min(r, k.radius_m);
  return r;
}

double Bat::PartRadiusM(bool at_tip) const {
  if (knots.empty()) return 0.0;
  const std::size_t i = at_tip ? knots.size() - 1 : 0;
  const double r = knots[i].radius_m;
  double wall = IsHollow() ? KnotWallM(i) : 0.0;
  if (!at_tip && handle.has_value()) wall = handle->WallM(wall);  // the handle's own wall
  return wall > 0.0 ? std::max(r - wall, 0.0) : r;
}

Bat MakeThreeSegmentBat(const ThreeSegmentShape& shape, const Material& material) {
  Bat bat;
  bat.knots = shape.Knots();
  bat.material = material;
  return bat;
}

}  // namespace sweetspot::core
