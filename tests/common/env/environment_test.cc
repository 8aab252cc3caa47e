// The spec's action kinds (continuous, Discrete, MultiDiscrete, masked) and
// the checks every environment and the learner apply to actions, masks and
// action layouts, each refusal naming what is wrong.

#include "common/env/environment.h"

#include <functional>
#include <string>
#include <vector>

#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace vantage {
namespace {

using ::testing::HasSubstr;

EnvSpec MultiDiscrete() {
  EnvSpec spec;
  spec.name = "multi";
  spec.observation_size = 3;
  spec.discrete = true;
  spec.action_nvec = {3, 2, 4};
  spec.action_size = 9;
  return spec;
}

TEST(EnvironmentTest, ActionKindsHaveTheirWidthsHeadsAndNames) {
  EnvSpec continuous;
  continuous.action_size = 6;
  EnvSpec discrete;
  discrete.discrete = true;
  discrete.action_size = 4;
  EnvSpec masked = discrete;
  masked.action_masks = true;
  const EnvSpec multi = MultiDiscrete();
  EXPECT_EQ(continuous.ActionString(), "continuous:6");
  EXPECT_EQ(discrete.ActionString(), "discrete:4");
  EXPECT_EQ(masked.ActionString(), "discrete:4 masked");
  EXPECT_EQ(multi.ActionString(), "multidiscrete:3x2x4");
  EXPECT_EQ(continuous.action_width(), 6);
  EXPECT_EQ(discrete.action_width(), 1);
  EXPECT_EQ(multi.action_width(), 3);
  EXPECT_TRUE(continuous.action_heads().empty());
  EXPECT_EQ(discrete.action_heads(), std::vector<int64_t>({4}));
  EXPECT_EQ(multi.action_heads(), std::vector<int64_t>({3, 2, 4}));
}

TEST(EnvironmentTest, AMultiDiscreteActionHasOneIndexPerHeadInItsRange) {
  const EnvSpec spec = MultiDiscrete();
  EXPECT_TRUE(CheckAction(spec, {2, 1, 3}).ok());
  EXPECT_THAT(CheckAction(spec, {2, 1}).message(),
              HasSubstr("action has 2 values, expected 3"));
  EXPECT_THAT(
      CheckAction(spec, {2, 2, 0}).message(),
      HasSubstr("discrete action value 1 2 is not an integer in [0, 2)"));
  EXPECT_THAT(CheckAction(spec, {0.5, 0, 0}).message(),
              HasSubstr("value 0 0.5 is not an integer in [0, 3)"));
}

TEST(EnvironmentTest, MasksHaveALegalChoiceInEveryHead) {
  EnvSpec spec = MultiDiscrete();
  spec.action_masks = true;
  EXPECT_TRUE(CheckActionMask(spec, {0, 0, 1, 1, 0, 0, 1, 0, 0}).ok());
  EXPECT_THAT(CheckActionMask(spec, {0, 0, 1, 0, 0, 0, 1, 0, 0}).message(),
              HasSubstr("the action mask is all zero for value 1"));
  EXPECT_THAT(CheckActionMask(spec, {1, 1}).message(),
              HasSubstr("the action mask has 2 entries, expected 9"));
  EXPECT_THAT(CheckActionMask(spec, {0, 0, 1, 1, 0, 0, 2, 0, 0}).message(),
              HasSubstr("action mask entry 6 is 2, expected 0 or 1"));
  EnvSpec discrete;
  discrete.name = "one";
  discrete.discrete = true;
  discrete.action_size = 3;
  discrete.action_masks = true;
  EXPECT_THAT(CheckActionMask(discrete, {0, 0, 0}).message(),
              HasSubstr("the action mask is all zero (no legal action)"));
  discrete.action_masks = false;
  EXPECT_THAT(CheckActionMask(discrete, {1, 0, 0}).message(),
              HasSubstr("which take none"));
}

TEST(EnvironmentTest, AMultiDiscreteLayoutSumsToTheLogits) {
  EnvSpec spec = MultiDiscrete();
  EXPECT_TRUE(CheckActionLayout(spec).ok());
  spec.action_size = 10;
  EXPECT_THAT(CheckActionLayout(spec).message(),
              HasSubstr("spec.action_nvec: 3x2x4 sums to 9, expected "
                        "action_size 10"));
  spec = MultiDiscrete();
  spec.action_nvec = {3, 0, 6};
  EXPECT_THAT(CheckActionLayout(spec).message(),
              HasSubstr("expected choices in [1, action_size 9] each"));
  spec = MultiDiscrete();
  spec.discrete = false;
  EXPECT_THAT(CheckActionLayout(spec).message(),
              HasSubstr("for continuous actions"));
}

// A camera image of 2x3x3 bytes and 4 joint values.
EnvSpec DictSpec() {
  EnvSpec spec;
  spec.name = "dict";
  spec.observation_size = 22;
  spec.observation_keys = {{"camera", 18, {2, 3, 3}, 255},
                           {"joints", 4, {}, 0}};
  spec.action_size = 1;
  return spec;
}

TEST(EnvironmentTest, DictEntriesFillTheRowAndNameEveryDefect) {
  EXPECT_TRUE(CheckObservationLayout(DictSpec()).ok());
  EXPECT_EQ(DictSpec().ObservationString(),
            "dict(camera: uint8 2x3x3, joints: 4)");
  struct Case {
    std::function<void(EnvSpec&)> change;
    std::string message;
  };
  const std::vector<Case> cases = {
      {[](EnvSpec& s) { s.observation_size = 23; },
       "sizes sum to 22, expected observation_size 23"},
      {[](EnvSpec& s) { s.observation_keys[1].name = "camera"; },
       "\"camera\" appears twice"},
      {[](EnvSpec& s) { s.observation_keys[0].name.clear(); },
       "observation_keys[0] (\"\"): an empty name"},
      {[](EnvSpec& s) { s.observation_keys[0].high = 0; },
       "(\"camera\"): high 0, expected 1..255 for an image"},
      {[](EnvSpec& s) { s.observation_keys[1].high = 3; },
       "(\"joints\"): high 3 for a vector"},
      {[](EnvSpec& s) {
         s.observation_keys[0].shape = {2, 3, 2};
       },
       "shape 2x3x2 does not hold its size 18"},
      {[](EnvSpec& s) { s.observation_keys[0].shape = {18}; },
       "expected [channels, height, width]"},
      {[](EnvSpec& s) { s.observation_high = 255; },
       "a Dict observation is a float row"},
  };
  for (const Case& c : cases) {
    EnvSpec spec = DictSpec();
    c.change(spec);
    EXPECT_THAT(CheckObservationLayout(spec).message(), HasSubstr(c.message))
        << c.message;
  }
}

}  // namespace
}  // namespace vantage
