// The api's half of barrel, bbcor and bbcor_scan (core's: core/scene/outputs_barrel.cpp; their
// blocks: BarrelOutputToJson, BbcorToJson and BbcorScanToJson, api/scene_render.cpp).
#include "api/outputs/scene_outputs.hpp"
#include "api/scene_json.hpp"

namespace sweetspot::api {
namespace outputs_barrel_api {
namespace {

using Json = nlohmann::json;

void RenderBarrel(const core::SceneResult& r, Json* out, Json*) {
  (*out)["barrel"] = BarrelOutputToJson(*r.barrel);
}

void ProbeBarrel(core::SceneResult* r) {
  r->barrel.emplace();
  r->barrel->hollow = true;  // every field a number
  r->barrel->effective_cor_curve.emplace_back();
}

void RenderBbcor(const core::SceneResult& r, Json* out, Json* errors) {
  (*out)["bbcor"] = BbcorToJson(*r.bbcor);
  (*errors)["bbcor"] = {{"value", r.bbcor->error_estimate}};
}

void ProbeBbcor(core::SceneResult* r) {
  r->bbcor.emplace();
  r->bbcor->method = core::kCertifiedBbcorMethod;
  r->bbcor->barrel_stiffness_n_m = 1.0;  // every field a number
}

void RenderBbcorScan(const core::SceneResult& r, Json* out, Json* errors) {
  (*out)["bbcor_scan"] = BbcorScanToJson(*r.bbcor_scan);
  (*errors)["bbcor_scan"] = {{"value", r.bbcor_scan->error_estimate}};
}

void ProbeBbcorScan(core::SceneResult* r) {
  r->bbcor_scan.emplace();
  r->bbcor_scan->points.emplace_back();
}

}  // namespace
}  // namespace outputs_barrel_api

extern const ApiOutputDecl kBarrelApi{core::SceneOutput::kBarrel, outputs_barrel_api::RenderBarrel,
                                      outputs_barrel_api::ProbeBarrel};
extern const ApiOutputDecl kBbcorApi{core::SceneOutput::kBbcor, outputs_barrel_api::RenderBbcor,
                                     outputs_barrel_api::ProbeBbcor};
extern const ApiOutputDecl kBbcorScanApi{core::SceneOutput::kBbcorScan,
                                         outputs_barrel_api::RenderBbcorScan,
                                         outputs_barrel_api::ProbeBbcorScan};

}  // namespace sweetspot::api
