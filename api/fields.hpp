// The settable fields of a request, declared once (issue 33, item 2): each field's path, SI
// unit, valid range, the accessor into the core structs, and which of the request's
// vocabularies take it (a swept parameter bound by /v1/explore's DesignBinder, a /v1/optimize
// variable, a /v1/bat/fit unknown of the three-segment fit). Every field's trade forms
// ("_in", "_oz", "_mph", "_oz_in2", "diameter_" for a radius: api/trade_units.hpp) come from
// its SI name, so a path is accepted in every form wherever the field is, and an answer or an
// error names it as the user wrote it. Core stays SI: the conversion happens here only.
//
// Adding a field: a row of Fields() (fields.cpp) with its accessor, in its object's reading
// order (the request's parser reads each object's numbers with ReadFieldGroup, in the table's
// order); core's own name for it (DesignVariableKind, for an optimiser variable and for
// a fit unknown) when those take it. FieldsTest round-trips every row through the parser, the
// binder and the optimiser's variables.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "api/json_reader.hpp"
#include "core/bat/bat.hpp"
#include "core/scene/scene.hpp"

namespace sweetspot::api {

/// The part of a request a field belongs to: where it sits, what it changes.
enum class FieldGroup {
  kBall,          ///< "ball.*": the pitched ball.
  kSwing,         ///< "swing.*".
  kCor,           ///< "cor".
  kContact,       ///< "contact.*": where across the bat the ball meets it.
  kShape,         ///< "bat.three_segment.*": a three-segment bat's shape.
  kKnot,          ///< "bat.profile.knots[i].*": a profile bat's knot.
  kMaterial,      ///< "bat.material.*": a material given as an object.
  kWall,          ///< "bat.wall_thickness_m".
  kFill,          ///< "bat.fill.*" (its size).
  kFillMaterial,  ///< "bat.fill.material.*".
  kEndCap,        ///< "bat.end_cap.*": its mass and length.
  kKnob,          ///< "bat.knob.*": its mass and length.
  kHandle,        ///< "bat.handle.*": a two-piece bat's joint and handle wall.
};

/// Where a field's accessor reads and writes: the parts of a request a field sits in, each null
/// where the caller has no such part (the parser reading a three-segment object has only its
/// shape), and a knot's index.
struct FieldHost {
  core::Ball* ball = nullptr;
  core::Swing* swing = nullptr;
  std::optional<double>* cor = nullptr;
  core::Contact* contact = nullptr;
  core::Bat* bat = nullptr;                  ///< Knots, wall, end cap, knob, handle.
  core::Material* material = nullptr;        ///< The bat's material (a material object's rows).
  core::ThreeSegmentShape* shape = nullptr;  ///< A three-segment bat's shape.
  core::Fill* fill = nullptr;                ///< The bat's fill.
  std::size_t knot = 0;

  /// Every part of `scene` (its bat's material, and fill when it has one), and `shape`.
  static FieldHost Of(core::Scene* scene, core::ThreeSegmentShape* shape = nullptr);
};

/// One settable field.
struct Field {
  /// From the request's root, a knot's index written "[]": "bat.three_segment.taper_start_m",
  /// "bat.profile.knots[].radius_m", "ball.speed_mps", "cor". Its SI name: the trade forms
  /// follow from it (TradeForms of the last key).
  std::string_view path;
  std::string_view unit;  ///< Its SI unit ("m", "kg", "m/s", "kg/m³", "Pa", "1").
  FieldGroup group;
  /// Its valid range, SI, as the request's reader and core's Validate hold it (the tighter
  /// rules between fields, x1 <= x2 or a wall below the radius, are core's).
  double min = 0.0;
  double max = 0.0;
  bool swept = false;     ///< DesignBinder binds it (/v1/explore parameters without JSON).
  bool variable = false;  ///< A /v1/optimize variable (its path without "bat.").
  /// Its name as a /v1/bat/fit unknown of the three-segment fit ("taper_start_m",
  /// "density_kg_m3", "fill.depth_m"); empty when the fit does not take it.
  std::string_view fit_name;
  /// The accessor: the field's value in `host`, and the setter (with what setting it implies:
  /// a material's shear modulus or Poisson's ratio given is no longer assumed).
  double (*get)(const FieldHost& host) = nullptr;
  void (*set)(const FieldHost& host, double value_si) = nullptr;
  /// Required in its object when the parser reads its group (ReadFieldGroup, FieldPresence::
  /// kAsDeclared): a shape's, a knot's, a fill's size, a material's density and Young's.
  bool required = false;
};

/// Every settable field, once.
const std::vector<Field>& Fields();

/// The field's key in its object: the last key of its path ("taper_start_m").
std::string_view FieldKey(const Field& field);

/// Whether ReadFieldGroup requires a field.
enum class FieldPresence {
  kAsDeclared,   ///< Its row's `required`.
  kAllOptional,  ///< None (a material over a catalogue "base": each field overrides the base's).
};

/// Reads the fields of `group` from `reader`'s object by their keys (each also in its trade
/// forms, as ObjectReader reads a number), in the table's order, into `host`: a required one
/// with ObjectReader::Number, an optional one with MaybeNumber (an absent one leaves the host's
/// value as it is). `given`, when not null, gets each field the object gave. False when the
/// reader has an error. The request's parser reads every object's numbers this way: the
/// three-segment shape, a profile's knots, a material, the wall, the fill's size, the ball, the
/// swing and the COR.
bool ReadFieldGroup(ObjectReader& reader, FieldGroup group, const FieldHost& host,
                    FieldPresence presence = FieldPresence::kAsDeclared,
                    std::vector<const Field*>* given = nullptr);

/// True when `field`'s path is `pattern` (SI, a knot's index as "[]").
inline bool IsField(const Field* field, std::string_view pattern) {
  return field != nullptr && field->path == pattern;
}

/// The field whose path (SI, indices as "[]") is `pattern`, or nullptr.
const Field* FindField(std::string_view pattern);

/// A field as the user wrote it.
struct FieldUse {
  const Field* field = nullptr;
  std::string written;  ///< As written ("three_segment.taper_start_in").
  std::string si;       ///< Its SI spelling in the same scope ("three_segment.taper_start_m").
  double to_si = 1.0;   ///< SI value = written value * to_si (0.0254 for inches).
  std::vector<std::size_t> indices;  ///< A knot's index.
};

/// Which names a vocabulary takes.
enum class FieldScope {
  kRequest,   ///< Paths from the request's root (explore parameters): "bat.fill.depth_m".
  kVariable,  ///< /v1/optimize variables: paths from the bat ("fill.depth_m").
  kFitName,   ///< Unknowns of the three-segment /v1/bat/fit: fit names ("taper_end_m").
};

/// The field `written` names in `scope`, in SI or any trade form ("wall_thickness_in",
/// "three_segment.barrel_diameter_in", "profile.knots[2].diameter_in", "fill.diameter_in"),
/// or nullopt.
std::optional<FieldUse> ResolveField(std::string_view written, FieldScope scope);

/// Every name `scope` takes, in SI and in each trade form (knots as "knots[i]"): the list a
/// typo's "did you mean" is drawn from.
std::vector<std::string> FieldNames(FieldScope scope);

/// " (did you mean \"NAME\"?)" for the name of `scope` one typo away from `written` ("" when
/// none is), a knot's index kept as written.
std::string DidYouMeanField(std::string_view written, FieldScope scope);

}  // namespace sweetspot::api
