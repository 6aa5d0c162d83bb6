// What the two contact models share around the event integrator
// (core/collision/contact_integration.hpp): the events of one contact, the integrator's settings
// for a contact and the opening of a solve.
#include "core/collision/contact_integration.hpp"
#include "core/collision/flexible_impact.hpp"
#include "core/collision/hertz_contact.hpp"

#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "tests/refusal_text.hpp"

namespace sweetspot::core {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace contact_integration_test {
namespace {

struct Checked {
  bool valid = true;
  std::string why;
  bool Validate(Refusal* out) const {
    if (!valid && out != nullptr) *out = TextRefusal("", why);  // Message() == why
    return valid;
  }
};

TEST(ContactIntegrationTest, LoadingWatchesMaximumCompressionUnloadingTheReload) {
  const auto loading = ContactEvents(false);
  ASSERT_EQ(loading.size(), 2u);
  EXPECT_EQ(loading[0].id, kMaxCompression);
  EXPECT_EQ(loading[1].id, kEnd);
  const auto unloading = ContactEvents(true);
  ASSERT_EQ(unloading.size(), 2u);
  EXPECT_EQ(unloading[0].id, kEnd);
  EXPECT_EQ(unloading[1].id, kReload);
  EXPECT_TRUE(unloading[1].fires_if_already_passed);
  EXPECT_FALSE(loading[0].fires_if_already_passed);
}

TEST(ContactIntegrationTest, IntegratorSettingsAreValidForAContact) {
  const EventIntegratorOptions o = ContactIntegratorOptions(1e-9, 2000, 3e-5);
  EXPECT_EQ(o.relative_tolerance, 1e-9);
  EXPECT_EQ(o.absolute_tolerance, 1e-9);
  EXPECT_EQ(o.max_steps, 2000);
  EXPECT_EQ(o.time_unit_s, 3e-5);
  EXPECT_STREQ(o.subject, "the contact");
  std::string why;
  EXPECT_TRUE(Validates(o, &why)) << why;
}

TEST(ContactIntegrationTest, StartContactSolveRefusesWithTheFirstInvalidInput) {
  Summary s;
  EXPECT_TRUE(StartContactSolve("hertz", &s, Checked{}, Checked{}));
  EXPECT_EQ(s.backend, "odeint:runge_kutta_dopri5");
  EXPECT_EQ(s.models_used, std::vector<std::string>{"hertz"});
  EXPECT_EQ(s.message, "");
  s = Summary{};
  EXPECT_FALSE(StartContactSolve("flexible", &s, Checked{true, "a"}, Checked{false, "b = 0: rule"},
                                 Checked{false, "c = 0: rule"}));
  EXPECT_EQ(s.termination, Termination::kInvalidInput);
  EXPECT_EQ(s.message, "b = 0: rule");
  EXPECT_EQ(s.models_used, std::vector<std::string>{"flexible"});
}

// The integrator's and the ball law's rules are written once (ContactIntegrationValidate,
// BallLawValidate) and both models refuse with them, each under its own field prefix; the texts
// are the ones the api and the hard-case tables assert.
TEST(ContactIntegrationTest, BothModelsRefuseTheSharedRulesWithTheirOwnPrefix) {
  std::string hertz_why, flexible_why;
  HertzSolverOptions hertz;
  hertz.max_steps = 9;
  FlexibleImpactOptions flexible;
  flexible.max_steps = 9;
  EXPECT_FALSE(Validates(hertz, &hertz_why));
  EXPECT_FALSE(Validates(flexible, &flexible_why));
  EXPECT_EQ(hertz_why, "hertz.max_steps = 9: must be >= 10");
  EXPECT_EQ(flexible_why, "flexible.max_steps = 9: must be >= 10");

  hertz = HertzSolverOptions{};
  hertz.relative_tolerance = 0.5;
  EXPECT_FALSE(Validates(hertz, &hertz_why));
  EXPECT_EQ(hertz_why, "hertz.relative_tolerance = 0.5: must be in [1e-13, 1e-2]");

  Refusal ball_why;
  EXPECT_TRUE(BallLawValidate(1e7, 1.5, &ball_why));
  EXPECT_FALSE(BallLawValidate(1e7, 3.5, &ball_why));
  EXPECT_EQ(ball_why.field, "ball.stiffness_exponent");
  EXPECT_EQ(ball_why.value, 3.5);
  EXPECT_EQ(ball_why.Message(), "ball.stiffness_exponent = 3.5: must be in [1, 3]");
  EXPECT_FALSE(BallLawValidate(0.0, 1.5, nullptr));  // nothing to write, still refused
}

}  // namespace
}  // namespace contact_integration_test
}  // namespace sweetspot::core
