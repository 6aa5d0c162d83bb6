// The outputs of the barrel model: barrel (hoop mode, stiffness, effective COR; scene_barrel.hpp),
// bbcor (THE BBCOR: the scan's maximum with the fixed-point estimate beside it; issue 35) and
// bbcor_scan (BBCOR along the barrel by the flexible model; core/collision/bbcor_scan.hpp).
#include <string>

#include "core/scene/output_registry.hpp"
#include "core/scene/scene_barrel.hpp"

namespace sweetspot::core {
namespace outputs_barrel {
namespace {

// The resolved mass properties when they are the rigid body's (what the barrel models use),
// else null (the models then compute the rigid body's themselves).
const MassProperties* SceneRigidBodyProperties(const ResolvedScene& r) {
  return r.mass_properties.inertia_model == InertiaModel::kRigidBody ? &r.mass_properties : nullptr;
}

void ComputeBarrel(OutputContext& c) {
  const auto tb = c.book.Now();
  BarrelOutput barrel;
  std::string error;
  if (SceneBarrel(c.scene, c.resolved, c.options.barrel, &barrel, &error)) {
    c.out.barrel = std::move(barrel);
  } else {
    c.Note(Termination::kFailure, error);
  }
  c.book.Add(kBarrelModel, c.book.Since(tb), 1);
}

// The scan of the scene's bat with the scene's impact and barrel options, booked.
BbcorScan SceneScan(OutputContext& c) {
  // The flexible impacts along the barrel (and, inside, the barrel model's fixed point:
  // microseconds, booked with them).
  const auto tb = c.book.Now();
  BbcorScan scan =
      ComputeBbcorScan(*c.scene.bat, *c.modes, BbcorProtocol{}, c.options.flexible.impact,
                       c.options.barrel, SceneRigidBodyProperties(c.resolved));
  const double seconds = c.book.Since(tb);
  c.book.Add(CollisionModelName(CollisionModel::kFlexible), seconds,
             static_cast<int>(scan.points.size()) + scan.polish_impacts);
  c.book.Add(kBarrelModel, 0.0, 1);
  return scan;
}

// THE BBCOR (issue 35): the scan's maximum with the fixed-point estimate beside it
// (CertifiedBbcorOf). The scan is computed here; when the scene also asks for bbcor_scan (next
// in the table) it is kept in that slot and not computed twice.
void ComputeBbcorOutput(OutputContext& c) {
  BbcorScan scan = SceneScan(c);
  BbcorResult bbcor = CertifiedBbcorOf(scan);
  for (const auto& w : bbcor.warnings) c.Warn(SceneOutput::kBbcor, w);
  if (!bbcor.ok) {
    c.Note(Termination::kFailure, bbcor.message);
    return;
  }
  c.out.bbcor = std::move(bbcor);
  if (c.Wants(SceneOutput::kBbcorScan)) {
    for (const auto& w : scan.warnings) c.Warn(SceneOutput::kBbcorScan, w);
    c.out.bbcor_scan = std::move(scan);
  }
}

void ComputeBbcorScanOutput(OutputContext& c) {
  if (c.out.bbcor_scan.has_value()) return;  // computed by bbcor
  BbcorScan scan = SceneScan(c);
  for (const auto& w : scan.warnings) c.Warn(SceneOutput::kBbcorScan, w);
  if (scan.ok) {
    c.out.bbcor_scan = std::move(scan);
  } else {
    c.Note(Termination::kFailure, scan.message);
  }
}

}  // namespace
}  // namespace outputs_barrel

extern const SceneOutputDecl kBarrelOutput{
    SceneOutput::kBarrel,
    "barrel",
    /*uses_exit_model=*/false,
    /*models=*/{"mass_properties", kBarrelModel},
    /*needs_geometry=*/true,
    /*needs_cor=*/true,  // the effective COR starts from the ball's (the resolved COR)
    OutputModes::kNone,
    "",
    /*needs_output=*/SceneOutput::kBarrel,
    OutputWorkload::kLight,
    outputs_barrel::ComputeBarrel,
    SlotPresent<&SceneOutputResults::barrel>,
    ResetSlot<&SceneOutputResults::barrel>,
    nullptr,
};

extern const SceneOutputDecl kBbcorOutput{
    SceneOutput::kBbcor,
    "bbcor",
    /*uses_exit_model=*/false,
    /*models=*/{"mass_properties", kFlexibleBeamModel, "flexible", kBarrelModel},
    /*needs_geometry=*/true,
    /*needs_cor=*/false,
    OutputModes::kImpact,
    /*modes_failure=*/"the bat's modes: ",
    /*needs_output=*/SceneOutput::kBbcor,
    OutputWorkload::kCompute,
    outputs_barrel::ComputeBbcorOutput,
    SlotPresent<&SceneOutputResults::bbcor>,
    ResetSlot<&SceneOutputResults::bbcor>,
    nullptr,
};

extern const SceneOutputDecl kBbcorScanOutput{
    SceneOutput::kBbcorScan,
    "bbcor_scan",
    /*uses_exit_model=*/false,
    /*models=*/{"mass_properties", kFlexibleBeamModel, "flexible", kBarrelModel},
    /*needs_geometry=*/true,
    /*needs_cor=*/false,
    OutputModes::kImpact,
    /*modes_failure=*/"the bat's modes: ",
    /*needs_output=*/SceneOutput::kBbcorScan,
    OutputWorkload::kCompute,
    outputs_barrel::ComputeBbcorScanOutput,
    SlotPresent<&SceneOutputResults::bbcor_scan>,
    ResetSlot<&SceneOutputResults::bbcor_scan>,
    nullptr,
};

}  // namespace sweetspot::core
