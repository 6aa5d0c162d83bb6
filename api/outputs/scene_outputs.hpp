// The api's half of each scene output, declared against core's id (core/scene/output_id.hpp):
// how it renders to JSON, the placeholder result that shows every field a sweep's row of it can
// have (explore's RowShape and columns), and the fields a sweep reads straight from a design's
// result without rendering it (explore's direct accessors). Each output's declaration is in
// api/outputs/outputs_*.cpp, registered by one row of the table in scene_outputs.cpp;
// SceneResultToJson, RowShape and the direct columns read the table.
#pragma once

#include <nlohmann/json.hpp>

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "api/json_writer.hpp"
#include "core/scene/closed_form_designs.hpp"
#include "core/scene/evaluate_scene.hpp"
#include "core/scene/output_id.hpp"

namespace sweetspot::api {

/// A value a column reads from a design's outcome without a JSON row.
struct DirectValue {
  enum Kind { kMissing, kNumber, kUnsigned, kBool, kString } kind = kMissing;
  double number = 0.0;
  std::uint64_t count = 0;
  bool flag = false;
  std::string_view text;
};

/// A number value.
DirectValue Number(double v);
/// A text value (the view must outlive the row).
DirectValue Text(std::string_view v);

/// What a direct field reads of a feasible design's outputs: the result of a design evaluated in
/// full, or the lean path's numbers (core::ClosedFormDesign: max_exit_speed by a closed form).
struct OutputView {
  const core::SceneResult* result = nullptr;     ///< The full evaluation, or null.
  const core::ClosedFormDesign* lean = nullptr;  ///< The lean path's design, or null.
  std::string_view lean_model;                   ///< The lean path's exit-speed model.
};

/// A field of an output's block that a sweep reads directly: the same value, under the same
/// name, as the rendered block holds (ExploreEngineTest checks every one against the JSON row).
struct DirectField {
  const char* name;                             ///< The field's key in the output's block.
  bool number;                                  ///< A number (a trade-unit twin may convert it).
  DirectValue (*read)(const OutputView& view);  ///< Its value; kMissing when the output is absent.
};

/// The api's half of one output.
struct ApiOutputDecl {
  core::SceneOutput id;  ///< Core's id (the name, models and computation are core's).
  /// Writes the output's block into out[name] and its error estimates into errors[name]; called
  /// only when the result holds the output.
  void (*render)(const core::SceneResult& result, nlohmann::json* out, nlohmann::json* errors);
  /// Fills the output's slot of *result with placeholders and one element in each array, so that
  /// rendering it shows every field a row of that output can have.
  void (*probe)(core::SceneResult* result);
  const DirectField* direct_begin = nullptr;  ///< The fields read directly (may be none).
  const DirectField* direct_end = nullptr;
  /// The same block and error estimates written as text: the TextObject instance of the
  /// generic renderer whose TreeObject instance is `render` (RenderTree). Null: `render`'s
  /// trees are written as they are.
  void (*write)(const core::SceneResult& result, TextObject& out, TextObject& errors) = nullptr;
};

/// `render` for a generic renderer F<Out>(result, out, errors): its TreeObject instance.
template <void (*F)(const core::SceneResult&, TreeObject&, TreeObject&)>
void RenderTree(const core::SceneResult& result, nlohmann::json* out, nlohmann::json* errors) {
  TreeObject block(out);
  TreeObject error(errors);
  F(result, block, error);
}

/// Every output's api declaration, in core's table order.
const std::vector<const ApiOutputDecl*>& ApiOutputTable();
/// The api declaration of `id`.
const ApiOutputDecl& ApiOutputDeclaration(core::SceneOutput id);

/// The outputs of a scene result, by output name, plus models_used,
/// error_estimate, timings, cor and properties.
nlohmann::json SceneResultToJson(const core::SceneResult& result);
/// The same members written to `out` (TreeObject or TextObject), with `warnings` after the
/// result's own in "warnings" (as AppendWarnings adds them to SceneResultToJson's).
template <class Out>
void WriteSceneResult(const core::SceneResult& result, const std::vector<std::string>& warnings,
                      Out& out);

/// A result holding every one of `outputs` as its probe fills it (RowShape's).
core::SceneResult ProbeResult(const std::vector<core::SceneOutput>& outputs);

}  // namespace sweetspot::api
