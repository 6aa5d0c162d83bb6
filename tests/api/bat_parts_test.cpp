// Issue 35, "bats as they are built": an end cap and a knob in a request (bat.end_cap,
// bat.knob: mass, length, material), in SI and trade units, their refusals and their answer.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "api/bat_json.hpp"
#include "api/router.hpp"
#include "core/bat/material.hpp"
#include "core/units.hpp"

namespace sweetspot::api {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace bat_parts_test {
namespace {

using Json = nlohmann::json;

Response Post(const std::string& path, const Json& body) {
  return Dispatch({"POST", path, body.dump()}, Context{});
}

Json Properties(const Json& bat) {
  const Response r = Post("/v1/bat/properties", Json{{"bat", bat}});
  EXPECT_EQ(r.status, 200) << r.body.dump();
  return r.body;
}

// The parts add their masses exactly and move the balance point by the closed form: a part
// of mass m centred at c moves the centroid from C0 (mass M0) to (M0 C0 + m c) / (M0 + m).
TEST(BatPartsTest, EndCapAndKnobAddTheirMassesInSiAndTradeUnits) {
  const Json bare = Properties(Json{{"preset", "bbcor-33-aluminium"}});
  const double m0 = bare["mass_kg"].get<double>();
  const double c0 = bare["balance_point_m"].get<double>();
  const double length = bare["length_m"].get<double>();
  // 1 oz over 0.5 in at the tip; 0.8 oz over 1 in at the knob.
  const double kOz = 0.028349523125, kIn = 0.0254;
  const Json capped =
      Properties(Json{{"preset", "bbcor-33-aluminium"},
                      {"end_cap", {{"mass_oz", 1.0}, {"length_in", 0.5}, {"material", "rubber"}}},
                      {"knob", {{"mass_kg", 0.8 * kOz}, {"length_m", kIn}}}});
  const double m = m0 + 1.0 * kOz + 0.8 * kOz;
  // Sums of three exact terms: 1e-14 relative.
  EXPECT_NEAR(capped["mass_kg"].get<double>(), m, 1e-14 * m);
  const double c = (m0 * c0 + kOz * (length - 0.25 * kIn) + 0.8 * kOz * 0.5 * kIn) / m;
  EXPECT_NEAR(capped["balance_point_m"].get<double>(), c, 1e-14 * c);
  EXPECT_GT(capped["moi_knob_kg_m2"].get<double>(), bare["moi_knob_kg_m2"].get<double>());
}

TEST(BatPartsTest, RefusalsNameTheFieldAsWritten) {
  const auto refused = [](const Json& bat) {
    const Response r = Post("/v1/bat/properties", Json{{"bat", bat}});
    EXPECT_EQ(r.status, 400) << r.body.dump();
    return r.body;
  };
  Json e = refused(Json{{"preset", "wood-34-ash"}, {"end_cap", {{"length_m", 0.01}}}});
  EXPECT_EQ(e["field"], "bat.end_cap.mass_kg") << e.dump();
  e = refused(Json{{"preset", "wood-34-ash"}, {"knob", {{"mass_oz", 1}, {"length_in", 40}}}});
  EXPECT_EQ(e["field"], "bat.knob.length_in") << e.dump();
  e = refused(Json{{"preset", "wood-34-ash"},
                   {"end_cap", {{"mass_kg", 0.02}, {"length_m", 0.01}, {"material", "lead"}}}});
  EXPECT_EQ(e["field"], "bat.end_cap.material") << e.dump();
  e = refused(Json{{"preset", "wood-34-ash"},
                   {"end_cap", {{"mass_kg", 0.02}, {"length_m", 0.01}, {"colour", "red"}}}});
  EXPECT_NE(e.dump().find("colour"), std::string::npos) << e.dump();
  // /v1/optimize's design model has no parts yet: refused, not optimised without them.
  const Response o = Post(
      "/v1/optimize",
      Json{{"bat", {{"preset", "wood-34-ash"}, {"knob", {{"mass_kg", 0.02}, {"length_m", 0.02}}}}},
           {"variables", {{{"path", "wall_thickness_m"}}}}});
  EXPECT_EQ(o.status, 400) << o.body.dump();
  EXPECT_EQ(o.body["field"], "bat.knob") << o.body.dump();
}

// The answer's bat carries its parts (BatToJson), and the flexible model sees them: the
// first bending mode drops with a heavy end cap (mass at the antinode, no stiffness).
TEST(BatPartsTest, PartsAreRenderedAndLowerTheFirstMode) {
  const Json cap = {{"mass_kg", 0.05}, {"length_m", 0.02}, {"material", "rubber"}};
  const Response r =
      Post("/v1/sweet-spot", Json{{"bat", {{"preset", "bbcor-33-aluminium"}, {"end_cap", cap}}},
                                  {"outputs", {"vibration_node"}}});
  ASSERT_EQ(r.status, 200) << r.body.dump();
  const Response bare = Post("/v1/sweet-spot", Json{{"bat", {{"preset", "bbcor-33-aluminium"}}},
                                                    {"outputs", {"vibration_node"}}});
  ASSERT_EQ(bare.status, 200);
  EXPECT_LT(r.body["vibration_node"]["frequency_hz"].get<double>(),
            bare.body["vibration_node"]["frequency_hz"].get<double>());
}

// Walls per knot in a request (profile.knots[i].wall_thickness_m or _in), against the closed
// form of a tube whose wall tapers linearly (WallPerKnotIsExact in core's tests), and refused
// on a solid bat with the field as written.
TEST(BatPartsTest, WallPerKnotInTradeUnits) {
  const double kIn = 0.0254, length = 33 * kIn, outer = 1.3125 * kIn, density = 2830.0;
  const double ta = 0.16 * kIn, tb = 0.09 * kIn;
  const Json material = {{"base", "aluminium-7050"}};
  const Json props =
      Properties(Json{{"profile",
                       {{"knots",
                         {{{"x_in", 0}, {"diameter_in", 2.625}, {"wall_thickness_in", 0.16}},
                          {{"x_in", 33}, {"diameter_in", 2.625}, {"wall_thickness_in", 0.09}}}}}},
                      {"material", material},
                      {"wall_thickness_in", 0.1}});
  const double sa = outer - ta, sb = outer - tb;
  const double mass =
      density * core::kPi * length * (outer * outer - (sa * sa + sa * sb + sb * sb) / 3.0);
  EXPECT_NEAR(props["mass_kg"].get<double>(), mass, 1e-12 * mass);  // inch conversions: 1e-12
  const Response r =
      Post("/v1/bat/properties",
           Json{{"bat",
                 {{"profile",
                   {{"knots",
                     {{{"x_m", 0}, {"radius_m", 0.03}},
                      {{"x_m", 0.8}, {"radius_m", 0.03}, {"wall_thickness_in", 0.1}}}}}}}}});
  EXPECT_EQ(r.status, 400) << r.body.dump();
  EXPECT_EQ(r.body["field"], "bat.profile.knots[1].wall_thickness_in") << r.body.dump();
}

// Issue 35: a two-piece bat in trade units, against the closed form of two cylinders: an aluminium
// tube (wall 0.1 in) from the joint (12 in) to the tip, a solid ash handle (wall 0) from the knob
// to the joint: m = rho pi (R^2 - r^2) l each, at its middle. The inch conversions and the
// sums of a few exact terms: 1e-12 relative.
TEST(BatPartsTest, TwoPieceBatInTradeUnitsIsTwoCylinders) {
  const double kIn = 0.0254, length = 33 * kIn, outer = 1.3125 * kIn, joint = 12 * kIn;
  const double inner = outer - 0.1 * kIn;
  const double rho_b = core::FindMaterial("aluminium-7050")->density_kg_m3;
  const double rho_h = core::FindMaterial("ash")->density_kg_m3;
  const Json cylinder = {
      {"knots", {{{"x_in", 0}, {"diameter_in", 2.625}}, {{"x_in", 33}, {"diameter_in", 2.625}}}}};
  const Json props = Properties(Json{
      {"profile", cylinder},
      {"material", "aluminium-7050"},
      {"wall_thickness_in", 0.1},
      {"handle", {{"material", "ash"}, {"joint_from_knob_in", 12}, {"wall_thickness_in", 0}}}});
  const double mh = rho_h * core::kPi * outer * outer * joint;
  const double mb = rho_b * core::kPi * (outer * outer - inner * inner) * (length - joint);
  const double mass = mh + mb;
  const double balance = (mh * 0.5 * joint + mb * 0.5 * (joint + length)) / mass;
  EXPECT_NEAR(props["mass_kg"].get<double>(), mass, 1e-12 * mass) << props.dump();
  EXPECT_NEAR(props["balance_point_m"].get<double>(), balance, 1e-12 * balance);
  // A handle of the bat's own material and wall is the one-piece bat, bit for bit (core's
  // TwoPieceOfOneMaterialIsTheOnePieceBatBitForBit: the two sides' difference is 0 exactly).
  const Json one = Properties(Json{{"preset", "bbcor-33-aluminium"}});
  const Json two =
      Properties(Json{{"preset", "bbcor-33-aluminium"},
                      {"handle", {{"material", "aluminium-7050"}, {"joint_from_knob_m", 0.3}}}});
  EXPECT_EQ(one["mass_kg"].get<double>(), two["mass_kg"].get<double>());
  EXPECT_EQ(one["moi_knob_kg_m2"].get<double>(), two["moi_knob_kg_m2"].get<double>());
}

TEST(BatPartsTest, TwoPieceRefusalsNameTheFieldAsWritten) {
  const auto refused = [](const Json& handle) {
    const Response r = Post("/v1/bat/properties",
                            Json{{"bat", {{"preset", "bbcor-33-aluminium"}, {"handle", handle}}}});
    EXPECT_EQ(r.status, 400) << r.body.dump();
    return r.body;
  };
  Json e = refused(Json{{"material", "ash"}, {"joint_from_knob_in", 40}});
  EXPECT_EQ(e["field"], "bat.handle.joint_from_knob_in") << e.dump();
  EXPECT_NE(e.dump().find("40"), std::string::npos) << e.dump();  // the value as written
  e = refused(Json{{"material", "ash"}, {"joint_from_knob_in", 12}, {"wall_thickness_in", 0.9}});
  EXPECT_EQ(e["field"], "bat.handle.wall_thickness_in") << e.dump();
  e = refused(Json{{"joint_from_knob_in", 12}});
  EXPECT_EQ(e["field"], "bat.handle.material") << e.dump();
  e = refused(Json{{"material", "unobtainium"}, {"joint_from_knob_in", 12}});
  EXPECT_EQ(e["field"], "bat.handle.material") << e.dump();
  // A material object past the caps (Bat::ValidateCaps: the handle's material too).
  e = refused(
      Json{{"material", {{"base", "ash"}, {"density_kg_m3", 1e9}}}, {"joint_from_knob_in", 12}});
  EXPECT_EQ(e["field"], "bat.handle.material.density_kg_m3") << e.dump();
  e = refused(Json{{"material", "ash"}});
  EXPECT_EQ(e["field"], "bat.handle.joint_from_knob_m") << e.dump();
  // /v1/optimize's design model has no handle: refused, not optimised as a one-piece bat.
  const Response o =
      Post("/v1/optimize", Json{{"bat",
                                 {{"preset", "bbcor-33-aluminium"},
                                  {"handle", {{"material", "ash"}, {"joint_from_knob_in", 12}}}}},
                                {"variables", {{{"path", "wall_thickness_m"}}}}});
  EXPECT_EQ(o.status, 400) << o.body.dump();
  EXPECT_EQ(o.body["field"], "bat.handle") << o.body.dump();
}

// The flexible model sees the handle: a solid ash handle (E 12 GPa against the tube's 72 GPa
// alloy) moves the first bending mode by more than 1 % (measured: see the message).
TEST(BatPartsTest, TwoPieceHandleMovesTheFirstMode) {
  const auto frequency = [](const Json& bat) {
    const Response r = Post("/v1/sweet-spot", Json{{"bat", bat}, {"outputs", {"vibration_node"}}});
    EXPECT_EQ(r.status, 200) << r.body.dump();
    return r.body["vibration_node"]["frequency_hz"].get<double>();
  };
  const double one = frequency(Json{{"preset", "bbcor-33-aluminium"}});
  const double two = frequency(Json{
      {"preset", "bbcor-33-aluminium"},
      {"handle", {{"material", "ash"}, {"joint_from_knob_in", 14}, {"wall_thickness_in", 0}}}});
  EXPECT_GT(std::abs(two / one - 1.0), 0.01) << one << " Hz, two-piece " << two << " Hz";
}

// The answer's bat (BatToJson: presets, /v1/optimize's designs) carries the handle, and what it
// renders parses back to the same bat: the same mass, bit for bit.
TEST(BatPartsTest, TwoPieceBatRendersAndParsesBack) {
  const Json request = {
      {"preset", "bbcor-33-aluminium"},
      {"handle", {{"material", "ash"}, {"joint_from_knob_in", 12}, {"wall_thickness_in", 0}}}};
  ApiError error;
  const auto spec = ParseBatGeometry(request, "bat", ApiLimits{}, &error);
  ASSERT_TRUE(spec) << error.message;
  const Json rendered = BatToJson(spec->bat);
  ASSERT_TRUE(rendered.contains("handle")) << rendered.dump();
  EXPECT_EQ(rendered["handle"]["material"], "ash");
  EXPECT_EQ(rendered["handle"]["wall_thickness_m"].get<double>(), 0.0);
  const auto back = ParseBatGeometry(rendered, "bat", ApiLimits{}, &error);
  ASSERT_TRUE(back) << error.message << " " << rendered.dump();
  ASSERT_TRUE(back->bat.handle.has_value());
  EXPECT_EQ(back->bat.handle->joint_from_knob_m, 12 * 0.0254);
  EXPECT_EQ(Properties(rendered)["mass_kg"].get<double>(),
            Properties(request)["mass_kg"].get<double>());
}

}  // namespace
}  // namespace bat_parts_test
}  // namespace sweetspot::api
