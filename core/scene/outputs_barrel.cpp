// The outputs of the barrel model: barrel (hoop mode, stiffness, effective COR; scene_barrel.hpp),
// bbcor (the NCAA protocol; core/collision/barrel.hpp) and bbcor_scan (BBCOR along the barrel
// by the flexible model; core/collision/bbcor_scan.hpp).
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

void ComputeBbcorOutput(OutputContext& c) {
  const auto tb = c.book.Now();
  BbcorResult bbcor = ComputeBbcor(*c.scene.bat, BbcorProtocol{}, c.options.barrel,
                                   SceneRigidBodyProperties(c.resolved));
  if (bbcor.ok) {
    c.out.bbcor = std::move(bbcor);
  } else {
    c.Note(Termination::kFailure, bbcor.message);
  }
  c.book.Add(kBarrelModel, c.book.Since(tb), 1);
}

void ComputeBbcorScanOutput(OutputContext& c) {
  // The flexible impacts along the barrel (and, inside, the barrel model's fixed point:
  // microseconds, booked with them).
  const auto tb = c.book.Now();
  BbcorScan scan =
      ComputeBbcorScan(*c.scene.bat, *c.modes, BbcorProtocol{}, c.options.flexible.impact,
                       c.options.barrel, SceneRigidBodyProperties(c.resolved));
  const double seconds = c.book.Since(tb);
  c.book.Add(CollisionModelName(CollisionModel::kFlexible), seconds,
             static_cast<int>(scan.points.size()));
  c.book.Add(kBarrelModel, 0.0, 1);
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
    /*models=*/{"mass_properties", kBarrelModel},
    /*needs_geometry=*/true,
    /*needs_cor=*/false,
    OutputModes::kNone,
    "",
    /*needs_output=*/SceneOutput::kBbcor,
    OutputWorkload::kLight,
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
