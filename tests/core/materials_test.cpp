// The materials catalogue and Material::Validate.
#include <gtest/gtest.h>

#include "tests/refusal_text.hpp"

#include <cmath>
#include <limits>
#include <set>
#include <string>

#include "core/bat/material.hpp"

namespace sweetspot::core {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace materials_test {
namespace {

TEST(MaterialsCatalogue, HasEveryEntryValidWithASource) {
  const std::set<std::string> expected = {
      "ash",        "hard-maple",     "yellow-birch",   "maple-bat-billet",
      "paper-wood", "aluminium-7046", "aluminium-7050", "carbon-epoxy-fabric",
      "cork",       "rubber"};
  std::set<std::string> names;
  for (const Material& m : MaterialCatalogue()) {
    std::string why;
    EXPECT_TRUE(Validates(m, &why)) << m.name << ": " << why;
    EXPECT_FALSE(m.source.empty()) << m.name;
    EXPECT_TRUE(names.insert(m.name).second) << "duplicate " << m.name;
  }
  EXPECT_EQ(names, expected);
}

TEST(MaterialsCatalogue, Values) {
  // Wood Handbook FPL-GTR-190: SG at 12 % x 1000 x 1.12 (exact products up to one rounding).
  EXPECT_NEAR(FindMaterial("ash")->density_kg_m3, 672.0, 1e-9);
  EXPECT_NEAR(FindMaterial("hard-maple")->density_kg_m3, 705.6, 1e-9);
  EXPECT_NEAR(FindMaterial("yellow-birch")->density_kg_m3, 694.4, 1e-9);
  EXPECT_EQ(FindMaterial("ash")->youngs_modulus_pa, 12.0e9);
  EXPECT_EQ(FindMaterial("hard-maple")->youngs_modulus_pa, 12.6e9);
  EXPECT_EQ(FindMaterial("yellow-birch")->youngs_modulus_pa, 13.9e9);
  const Material paper = *FindMaterial("paper-wood");
  EXPECT_EQ(paper.density_kg_m3, 649.0);
  EXPECT_EQ(paper.youngs_modulus_pa, 1.814e10);
  ASSERT_TRUE(paper.cor.has_value());
  EXPECT_EQ(*paper.cor, 0.5);
  EXPECT_EQ(*FindMaterial("aluminium-7050")->cor, 0.5);
  EXPECT_EQ(*FindMaterial("aluminium-7046")->cor, 0.5);
  const Material cork = *FindMaterial("cork");
  EXPECT_EQ(cork.density_kg_m3, 290.0);
  EXPECT_EQ(cork.density_min_kg_m3, 260.0);
  EXPECT_EQ(cork.density_max_kg_m3, 320.0);
  EXPECT_FALSE(cork.cor.has_value());
  EXPECT_FALSE(FindMaterial("rubber")->cor.has_value());
  // Bat-grade maple (Appl. Sci. 12(7), 3494, Appendix A, Profile B): psi x 6894.757293168.
  const Material billet = *FindMaterial("maple-bat-billet");
  EXPECT_EQ(billet.density_kg_m3, 637.0);
  EXPECT_NEAR(billet.youngs_modulus_pa, 2198507.0 * 6894.757293168, 1e-3);
  EXPECT_NEAR(billet.shear_modulus_pa, 244034.0 * 6894.757293168, 1e-3);
  EXPECT_EQ(billet.base, "hard-maple");  // its species, for league rules
  EXPECT_EQ(billet.kind, MaterialKind::kWood);
  // The composite (Performance Composites' "Std CF Fabric" column; SubsTech's density).
  const Material carbon = *FindMaterial("carbon-epoxy-fabric");
  EXPECT_EQ(carbon.kind, MaterialKind::kComposite);
  EXPECT_EQ(carbon.youngs_modulus_pa, 70.0e9);
  EXPECT_EQ(carbon.shear_modulus_pa, 5.0e9);
  EXPECT_EQ(carbon.density_kg_m3, 1600.0);
  EXPECT_FALSE(FindMaterial("balsa").has_value());
  EXPECT_FALSE(FindMaterial("").has_value());
}

TEST(MaterialsCatalogue, EffectiveShearModulus) {
  // Derived: E / (2 (1 + nu)) = 1.814e10 / 2.5.
  EXPECT_DOUBLE_EQ(FindMaterial("paper-wood")->EffectiveShearModulusPa(), 7.256e9);
  // Given: ash's G_LR = 0.109 E_L.
  EXPECT_DOUBLE_EQ(FindMaterial("ash")->EffectiveShearModulusPa(), 0.109 * 12.0e9);
  EXPECT_DOUBLE_EQ(FindMaterial("aluminium-7050")->EffectiveShearModulusPa(), 26.9e9);
}

TEST(MaterialsCatalogue, CatalogueIsStable) {
  EXPECT_EQ(&MaterialCatalogue(), &MaterialCatalogue());
}

TEST(MaterialValidity, SizesGivenFromOutsideAreCapped) {
  // Core computes beyond the caps (tests/hard_cases); ValidateSize holds a material given from
  // outside to them, each rule written from its bounds.
  Material m = *FindMaterial("ash");
  Refusal r;
  EXPECT_TRUE(m.ValidateSize(&r)) << r.Message();
  for (const Material& catalogued : MaterialCatalogue()) {
    EXPECT_TRUE(catalogued.ValidateSize(&r)) << catalogued.name << ": " << r.Message();
  }
  m.density_kg_m3 = kMaxDensityKgM3;  // the bound itself passes
  EXPECT_TRUE(m.ValidateSize(&r));
  m.density_kg_m3 = 2e5;
  EXPECT_TRUE(m.Validate(nullptr));
  ASSERT_FALSE(m.ValidateSize(&r));
  EXPECT_EQ(r.Message(), "density_kg_m3 = 2e+05: must be in (0, 1e+05]");
  m = *FindMaterial("ash");
  m.youngs_modulus_pa = 2e13;
  ASSERT_FALSE(m.ValidateSize(&r));
  EXPECT_EQ(r.Message(), "youngs_modulus_pa = 2e+13: must be in (0, 1e+13]");
  m = *FindMaterial("ash");
  m.shear_modulus_pa = 2e13;
  ASSERT_FALSE(m.ValidateSize(&r));
  EXPECT_EQ(r.Message(),
            "shear_modulus_pa = 2e+13: must be in [0, 1e+13] (0 = derive from poissons_ratio)");
  m.shear_modulus_pa = -1.0;  // Validate's own rule first
  ASSERT_FALSE(m.ValidateSize(&r));
  EXPECT_EQ(r.Message(),
            "shear_modulus_pa = -1: must be non-negative (0 = derive from poissons_ratio)");
}

TEST(MaterialValidity, Refusals) {
  const Material good = *FindMaterial("ash");
  struct Case {
    void (*edit)(Material&);
    const char* message;
  } cases[] = {
      {[](Material& m) { m.density_kg_m3 = 0.0; }, "density_kg_m3 = 0: must be positive"},
      {[](Material& m) { m.density_kg_m3 = -5.0; }, "density_kg_m3 = -5: must be positive"},
      {[](Material& m) { m.density_kg_m3 = std::numeric_limits<double>::infinity(); },
       "density_kg_m3 = inf: must be finite"},
      {[](Material& m) { m.youngs_modulus_pa = std::numeric_limits<double>::quiet_NaN(); },
       "youngs_modulus_pa = nan: must be finite"},
      {[](Material& m) { m.youngs_modulus_pa = 0.0; }, "youngs_modulus_pa = 0: must be positive"},
      {[](Material& m) { m.shear_modulus_pa = -1.0; },
       "shear_modulus_pa = -1: must be non-negative (0 = derive from poissons_ratio)"},
      {[](Material& m) { m.poissons_ratio = 0.5; },
       "poissons_ratio = 0.5: must be greater than -1 and less than 0.5"},
      {[](Material& m) { m.poissons_ratio = -1.0; },
       "poissons_ratio = -1: must be greater than -1 and less than 0.5"},
      {[](Material& m) { m.cor = 1.5; }, "cor = 1.5: must be between 0 and 1"},
      {[](Material& m) { m.cor = -0.1; }, "cor = -0.1: must be between 0 and 1"},
      {[](Material& m) { m.density_min_kg_m3 = -1.0; },
       "density_min_kg_m3 = -1: must be non-negative (0 = none)"},
      {[](Material& m) {
         m.density_min_kg_m3 = 800.0;
         m.density_max_kg_m3 = 600.0;
       },
       "density_min_kg_m3 = 800: must not exceed density_max_kg_m3 = 600"},
  };
  for (const Case& c : cases) {
    Material m = good;
    c.edit(m);
    std::string why;
    EXPECT_FALSE(Validates(m, &why)) << c.message;
    EXPECT_EQ(why, c.message);
    EXPECT_FALSE(m.Validate(nullptr)) << c.message;
  }
}

TEST(MaterialValidity, CustomMaterialsAndRanges) {
  Material custom;
  custom.name = "custom";
  custom.density_kg_m3 = 500.0;
  custom.youngs_modulus_pa = 1e10;
  std::string why;
  EXPECT_TRUE(Validates(custom, &why)) << why;
  EXPECT_FALSE(custom.cor.has_value());
  // The density range is informational: cork at 400 kg/m^3 is accepted.
  Material cork = *FindMaterial("cork");
  cork.density_kg_m3 = 400.0;
  EXPECT_TRUE(Validates(cork, &why)) << why;
  // The empty fill is not a material of its own.
  const Material empty = EmptyFillMaterial();
  EXPECT_EQ(empty.name, "empty");
  EXPECT_EQ(empty.density_kg_m3, 0.0);
  EXPECT_FALSE(empty.Validate(nullptr));
}

}  // namespace
}  // namespace materials_test
}  // namespace sweetspot::core
