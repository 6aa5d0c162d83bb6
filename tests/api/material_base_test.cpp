// Issue 19, "Materials from a base": {"base": NAME, ...overrides}, kinds and aliases in
// /v1/materials, league rules on the kind and species (not the name), and a custom material
// without G or nu is computed with nu = 0.3 but says so.
#include <gtest/gtest.h>

#include <map>
#include <string>

#include "api/router.hpp"
#include "core/bat/material.hpp"

namespace sweetspot::api {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace material_base_test {
namespace {

using Json = nlohmann::json;

Response Post(const std::string& path, const Json& body) {
  return Dispatch({"POST", path, body.dump()}, Context{});
}

Json ThreeSegment(const Json& material) {
  return {{"three_segment",
           {{"length_m", 0.8636},
            {"handle_radius_m", 0.0125},
            {"barrel_radius_m", 0.033},
            {"taper_start_m", 0.30},
            {"taper_end_m", 0.55}}},
          {"material", material}};
}

Json Optimize(const Json& material) {
  return {{"bat", ThreeSegment(material)},
          {"variables", {{{"path", "three_segment.taper_start_m"}, {"min", 0.1}, {"max", 0.5}}}},
          {"constraints", {{"rules", "mlb-wood"}}},
          {"options", {{"max_time_s", 2}, {"starts", 1}}}};
}

TEST(MaterialBaseTest, CatalogueListsKindAndAliases) {
  const Response r = Dispatch({"GET", "/v1/materials", ""}, Context{});
  ASSERT_EQ(r.status, 200);
  std::map<std::string, Json> by_name;
  for (const Json& m : r.body["materials"]) by_name[m["name"]] = m;
  EXPECT_EQ(by_name["hard-maple"]["kind"], "wood");
  EXPECT_EQ(by_name["hard-maple"]["aliases"], Json::array({"maple", "sugar-maple"}));
  EXPECT_EQ(by_name["yellow-birch"]["aliases"], Json::array({"birch"}));
  EXPECT_EQ(by_name["aluminium-7050"]["kind"], "metal");
  EXPECT_EQ(by_name["cork"]["kind"], "fill");
  EXPECT_EQ(by_name["ash"]["kind"], "wood");
}

TEST(MaterialBaseTest, AliasIsTheSameMaterial) {
  const Response alias = Post("/v1/bat/properties", {{"bat", ThreeSegment("maple")}});
  const Response name = Post("/v1/bat/properties", {{"bat", ThreeSegment("hard-maple")}});
  ASSERT_EQ(alias.status, 200) << alias.body.dump();
  ASSERT_EQ(name.status, 200) << name.body.dump();
  EXPECT_EQ(alias.body["mass_kg"], name.body["mass_kg"]);  // the same entry: bit-identical
}

TEST(MaterialBaseTest, BaseInheritsEverythingElse) {
  // Only the density overridden: the mass scales with it exactly, every other field is the
  // base's (the flexible beam's frequency uses E and G: equal E/rho ratio check below).
  const core::Material maple = *core::FindMaterial("hard-maple");
  const Response base =
      Post("/v1/bat/properties",
           {{"bat", ThreeSegment({{"base", "hard-maple"}, {"density_kg_m3", 650}})}});
  const Response named = Post("/v1/bat/properties", {{"bat", ThreeSegment("hard-maple")}});
  ASSERT_EQ(base.status, 200) << base.body.dump();
  const double ratio = 650.0 / maple.density_kg_m3;
  // Mass is linear in density; a few roundings (relative 1e-14).
  EXPECT_NEAR(base.body["mass_kg"].get<double>(), ratio * named.body["mass_kg"].get<double>(),
              1e-14 * named.body["mass_kg"].get<double>());
  // COR inherited: a scene takes the base's 0.5 (a custom object without cor has none).
  const Response scene =
      Post("/v1/collision", {{"bat", ThreeSegment({{"base", "maple"}, {"density_kg_m3", 650}})},
                             {"impact_from_knob_m", 0.7}});
  ASSERT_EQ(scene.status, 200) << scene.body.dump();
  EXPECT_EQ(scene.body["cor"], 0.5);
  EXPECT_EQ(scene.body["cor_source"], "material:custom");
  // A vibration node with the base's E and G equals one with them written out.
  const Json written = {{"density_kg_m3", 650},
                        {"youngs_modulus_pa", maple.youngs_modulus_pa},
                        {"shear_modulus_pa", maple.shear_modulus_pa},
                        {"poissons_ratio", maple.poissons_ratio},
                        {"cor", 0.5}};
  const Response a = Post("/v1/sweet-spot",
                          {{"bat", ThreeSegment({{"base", "hard-maple"}, {"density_kg_m3", 650}})},
                           {"outputs", {"vibration_node"}}});
  const Response b =
      Post("/v1/sweet-spot", {{"bat", ThreeSegment(written)}, {"outputs", {"vibration_node"}}});
  ASSERT_EQ(a.status, 200) << a.body.dump();
  ASSERT_EQ(b.status, 200) << b.body.dump();
  // The same numbers reach the same computation: bit-identical.
  EXPECT_EQ(a.body["vibration_node"]["frequency_hz"], b.body["vibration_node"]["frequency_hz"]);
}

TEST(MaterialBaseTest, UnknownBaseNamesFieldValueAndList) {
  const Response r = Post("/v1/bat/properties",
                          {{"bat", ThreeSegment({{"base", "oak"}, {"density_kg_m3", 650}})}});
  EXPECT_EQ(r.status, 400);
  EXPECT_EQ(r.body["field"], "bat.material.base");
  const std::string message = r.body["message"];
  EXPECT_NE(message.find("\"oak\""), std::string::npos) << message;
  EXPECT_NE(message.find("hard-maple (maple, sugar-maple)"), std::string::npos) << message;
}

TEST(MaterialBaseTest, MlbWoodChecksKindAndSpeciesNotName) {
  // Based on hard-maple, named otherwise: wood of an allowed species.
  const Response maple =
      Post("/v1/optimize",
           Optimize({{"base", "hard-maple"}, {"name", "hard-maple-30oz"}, {"density_kg_m3", 650}}));
  EXPECT_EQ(maple.status, 200) << maple.body.dump();
  EXPECT_EQ(Post("/v1/optimize", Optimize("birch")).status, 200);
  // A metal base: refused on bat.material whatever it is called.
  const Response metal =
      Post("/v1/optimize", Optimize({{"base", "aluminium-7050"}, {"name", "hard-maple"}}));
  EXPECT_EQ(metal.status, 400);
  EXPECT_EQ(metal.body["field"], "bat.material");
  EXPECT_NE(metal.body["message"].get<std::string>().find("of kind metal"), std::string::npos)
      << metal.body.dump();
  // Named "hard-maple" without a base: its kind is not known, so not allowed wood.
  const Response named = Post("/v1/optimize", Optimize({{"name", "hard-maple"},
                                                        {"density_kg_m3", 650},
                                                        {"youngs_modulus_pa", 1.2e10},
                                                        {"poissons_ratio", 0.42},
                                                        {"cor", 0.5}}));
  EXPECT_EQ(named.status, 400);
  EXPECT_EQ(named.body["field"], "bat.material");
}

TEST(MaterialBaseTest, OptimizedBasedMaterialEchoesAsARequestMaterial) {
  // A density variable on a based material: the answer's bat carries the base and can be sent
  // back as it is (no catalogue-only field such as kind).
  Json body = Optimize({{"base", "maple"}});
  body["variables"] = {{{"path", "material.density_kg_m3"}, {"min", 600}, {"max", 800}}};
  body["constraints"]["mass_kg"] = 1.05;
  const Response r = Post("/v1/optimize", body);
  ASSERT_EQ(r.status, 200) << r.body.dump();
  const Json& material = r.body["bat"]["material"];
  EXPECT_EQ(material["base"], "maple");
  EXPECT_FALSE(material.contains("kind")) << material.dump();
  const Response again = Post("/v1/bat/properties", {{"bat", r.body["bat"]}});
  ASSERT_EQ(again.status, 200) << again.body.dump();
  // The optimiser meets the mass equality to its constraint tolerance (Ipopt's default 1e-8
  // on the scaled problem; 1e-6 kg is far above it and far below any design change).
  EXPECT_NEAR(again.body["mass_kg"].get<double>(), 1.05, 1e-6);
}

TEST(MaterialBaseTest, CustomWithoutBaseWorksAsBeforeAndWarnsOnAssumedPoisson) {
  const Json custom = {{"density_kg_m3", 650}, {"youngs_modulus_pa", 1.2e10}, {"cor", 0.5}};
  const Response r = Post("/v1/sweet-spot", {{"bat", ThreeSegment(custom)}});
  ASSERT_EQ(r.status, 200) << r.body.dump();
  const std::string dump = r.body.dump();
  EXPECT_NE(dump.find("poissons_ratio = 0.3 assumed"), std::string::npos) << dump;
  // Given nu: no warning.
  Json with_nu = custom;
  with_nu["poissons_ratio"] = 0.42;
  const Response quiet = Post("/v1/sweet-spot", {{"bat", ThreeSegment(with_nu)}});
  ASSERT_EQ(quiet.status, 200) << quiet.body.dump();
  EXPECT_EQ(quiet.body.dump().find("assumed"), std::string::npos) << quiet.body.dump();
  // Without a base, density and E are still required.
  const Response missing =
      Post("/v1/bat/properties", {{"bat", ThreeSegment({{"density_kg_m3", 650}})}});
  EXPECT_EQ(missing.status, 400);
  EXPECT_EQ(missing.body["field"], "bat.material.youngs_modulus_pa");
}

}  // namespace
}  // namespace material_base_test
}  // namespace sweetspot::api
