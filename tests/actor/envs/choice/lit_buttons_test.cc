// LitButtons' rules: the lit buttons and their values come from the seed
// and change every step, the mask allows exactly the lit ones, a lit press
// earns its value, an unlit one is refused (masked) or costs 1 (unmasked);
// options, an exact save and restore, and a vector of them refusing an
// illegal action.

#include "actor/envs/choice/lit_buttons.h"

#include <numeric>
#include <vector>

#include "actor/envs/env_registry.h"
#include "actor/vector_env.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace vantage {
namespace {

using ::testing::HasSubstr;

std::unique_ptr<Environment> Make(const std::string& name) {
  absl::StatusOr<std::unique_ptr<Environment>> env = MakeEnvironment(name);
  EXPECT_TRUE(env.ok()) << env.status();
  return env.ok() ? *std::move(env) : nullptr;
}

std::vector<uint8_t> Mask(const Environment& env) {
  absl::StatusOr<std::vector<uint8_t>> mask = ReadActionMask(env);
  EXPECT_TRUE(mask.ok()) << mask.status();
  return mask.ok() ? *mask : std::vector<uint8_t>();
}

TEST(LitButtonsTest, TheMaskAllowsTheLitButtonsWhosePressEarnsTheirValue) {
  std::unique_ptr<Environment> env = Make("LitButtons:buttons=8,steps=5");
  const EnvSpec& spec = env->spec();
  EXPECT_EQ(spec.name, "LitButtons:buttons=8,steps=5");
  EXPECT_EQ(spec.ActionString(), "discrete:8 masked");
  EXPECT_EQ(spec.observation_size, 16);
  std::vector<double> observation(16);
  ASSERT_TRUE(env->Reset(3, absl::MakeSpan(observation)).ok());
  std::vector<std::vector<double>> seen;
  for (int step = 0; step < 5; ++step) {
    const std::vector<uint8_t> mask = Mask(*env);
    ASSERT_EQ(mask.size(), 8u);
    EXPECT_EQ(std::accumulate(mask.begin(), mask.end(), 0), 3);
    int pressed = -1;
    for (int i = 0; i < 8; ++i) {
      EXPECT_EQ(observation[i], mask[i]);  // the lit flags
      if (!mask[i]) EXPECT_EQ(observation[8 + i], 0.0);
      if (mask[i] && pressed < 0) pressed = i;
    }
    const double value = observation[8 + pressed];
    seen.push_back(observation);
    absl::StatusOr<StepResult> result =
        env->Step({static_cast<double>(pressed)}, absl::MakeSpan(observation));
    ASSERT_TRUE(result.ok()) << result.status();
    EXPECT_EQ(result->reward, value);
    EXPECT_EQ(result->terminated, step == 4);
  }
  EXPECT_NE(seen[0], seen[1]);  // a new panel every step
  // The same seed, the same panels.
  std::vector<double> again(16);
  ASSERT_TRUE(env->Reset(3, absl::MakeSpan(again)).ok());
  EXPECT_EQ(again, seen[0]);
}

TEST(LitButtonsTest, AnUnlitPressIsRefusedWhenMaskedAndCostsOneWhenNot) {
  for (const bool masked : {true, false}) {
    std::unique_ptr<Environment> env = Make(
        masked ? "LitButtons:buttons=6" : "LitButtons:buttons=6,masked=false");
    std::vector<double> observation(12);
    ASSERT_TRUE(env->Reset(9, absl::MakeSpan(observation)).ok());
    int unlit = 0;
    while (observation[unlit] == 1.0) ++unlit;
    const std::vector<double> before = observation;
    absl::StatusOr<StepResult> result =
        env->Step({static_cast<double>(unlit)}, absl::MakeSpan(observation));
    if (masked) {
      EXPECT_THAT(result.status().message(),
                  HasSubstr("button " + std::to_string(unlit) + " is not lit"));
      EXPECT_EQ(observation, before);
    } else {
      ASSERT_TRUE(result.ok()) << result.status();
      EXPECT_EQ(result->reward, -1.0);
      EXPECT_FALSE(env->spec().action_masks);
      std::vector<uint8_t> mask(6);
      EXPECT_TRUE(absl::IsUnimplemented(env->ActionMask(absl::MakeSpan(mask))));
    }
  }
}

TEST(LitButtonsTest, SavedStateRestoresThePanelAndItsMask) {
  std::unique_ptr<Environment> env = Make("LitButtons");
  std::unique_ptr<Environment> other = Make("LitButtons");
  std::vector<double> observation(64), unused(64);
  ASSERT_TRUE(env->Reset(4, absl::MakeSpan(observation)).ok());
  ASSERT_TRUE(other->Reset(5, absl::MakeSpan(unused)).ok());
  ASSERT_TRUE(env->Step({static_cast<double>(std::find(observation.begin(),
                                                       observation.end(), 1.0) -
                                             observation.begin())},
                        absl::MakeSpan(observation))
                  .ok());
  absl::StatusOr<std::string> state = env->SaveState();
  ASSERT_TRUE(state.ok()) << state.status();
  ASSERT_TRUE(other->RestoreState(*state).ok());
  EXPECT_EQ(Mask(*other), Mask(*env));
  const int legal =
      static_cast<int>(std::find(observation.begin(), observation.end(), 1.0) -
                       observation.begin());
  absl::StatusOr<StepResult> a =
      env->Step({static_cast<double>(legal)}, absl::MakeSpan(observation));
  absl::StatusOr<StepResult> b =
      other->Step({static_cast<double>(legal)}, absl::MakeSpan(unused));
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(a->reward, b->reward);
  EXPECT_EQ(observation, unused);
  const absl::Status refused =
      Make("LitButtons:buttons=8")->RestoreState(*state);
  EXPECT_THAT(refused.message(),
              HasSubstr("'LitButtons' in the state but 'LitButtons:buttons=8' "
                        "here"));
}

TEST(LitButtonsTest, ItsDictFormIsTheSameRowDescribedByItsHalves) {
  std::unique_ptr<Environment> plain = Make("LitButtons:buttons=4");
  std::unique_ptr<Environment> dict = Make("LitButtons:buttons=4,dict=true");
  EXPECT_EQ(dict->spec().ObservationString(), "dict(lit: 4, values: 4)");
  EXPECT_TRUE(CheckObservationLayout(dict->spec()).ok());
  std::vector<double> a(8), b(8);
  ASSERT_TRUE(plain->Reset(2, absl::MakeSpan(a)).ok());
  ASSERT_TRUE(dict->Reset(2, absl::MakeSpan(b)).ok());
  EXPECT_EQ(a, b);
}

TEST(LitButtonsTest, OptionsAreChecked) {
  EXPECT_THAT(MakeEnvironment("LitButtons:lit=5,buttons=4").status().message(),
              HasSubstr("lit=5 exceeds buttons=4"));
  EXPECT_THAT(MakeEnvironment("LitButtons:buttons=1").status().message(),
              HasSubstr("buttons"));
}

// A vector of masked envs exposes each env's mask, renewed after every
// step and reset, and refuses an illegal action by name: that env's step
// reads as failed and the others step.
TEST(LitButtonsTest, AVectorOfThemRefusesAnIllegalAction) {
  absl::StatusOr<std::unique_ptr<VectorEnv>> made =
      VectorEnv::Create("LitButtons:buttons=5,steps=2", 2, 7);
  ASSERT_TRUE(made.ok()) << made.status();
  VectorEnv& envs = **made;
  ASSERT_TRUE(envs.Reset().ok());
  const auto legal_actions = [&] {
    std::vector<double> actions;
    for (int e = 0; e < 2; ++e) {
      for (int i = 0; i < 5; ++i) {
        EXPECT_EQ(envs.action_masks()[e * 5 + i],
                  envs.observations()[e * 10 + i]);
      }
      actions.push_back(static_cast<double>(
          std::find(envs.action_masks().begin() + e * 5,
                    envs.action_masks().begin() + e * 5 + 5, 1) -
          (envs.action_masks().begin() + e * 5)));
    }
    return actions;
  };
  for (int step = 0; step < 4; ++step) {
    ASSERT_TRUE(envs.Step(legal_actions()).ok());
  }
  std::vector<double> actions = legal_actions();
  const int illegal = static_cast<int>(
      std::find(envs.action_masks().begin() + 5, envs.action_masks().end(), 0) -
      (envs.action_masks().begin() + 5));
  actions[1] = illegal;
  const absl::Status status = envs.Step(actions);
  EXPECT_THAT(status.message(),
              HasSubstr("env 1: LitButtons:buttons=5,steps=2: action " +
                        std::to_string(illegal) +
                        " is illegal in this state (its action mask is 0)"));
  EXPECT_GT(envs.rewards()[0], 0.0);
  EXPECT_EQ(envs.rewards()[1], 0.0);
}

}  // namespace
}  // namespace vantage
