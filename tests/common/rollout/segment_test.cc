#include "common/rollout/segment.h"

#include <ATen/ATen.h>

#include <cmath>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include "common/rollout/segment_queue.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace vantage {
namespace {

using ::testing::HasSubstr;

EnvSpec Spec() {
  EnvSpec spec;
  spec.name = "test";
  spec.observation_size = 3;
  spec.action_size = 2;
  return spec;
}

Segment ValidSegment() {
  Segment s;
  s.observations = at::zeros({5, 3});
  s.actions = at::zeros({4, 2});
  s.rewards = at::ones({4});
  s.terminated = at::zeros({4}, at::kBool);
  s.truncated = at::zeros({4}, at::kBool);
  s.truncated[2] = true;
  s.final_observations = at::zeros({1, 3});
  s.behaviour_log_probs = at::zeros({4});
  s.episode_returns = {2.0};
  s.episode_lengths = {3};
  return s;
}

TEST(SegmentTest, ValidSegmentPasses) {
  EXPECT_TRUE(ValidateSegment(ValidSegment(), Spec(), 128).ok());
}

// Four discrete actions whose legality the environment masks.
EnvSpec MaskedSpec() {
  EnvSpec spec = Spec();
  spec.discrete = true;
  spec.action_size = 4;
  spec.action_masks = true;
  return spec;
}

// ValidSegment's steps acting 0, 1, 2, 3 with masks that allow each.
Segment MaskedSegment() {
  Segment s = ValidSegment();
  s.actions = at::arange(4, at::kFloat).reshape({4, 1});
  s.action_masks = at::eye(4, at::kBool);
  s.action_masks[0][3] = true;
  return s;
}

TEST(SegmentTest, MaskedActionsNeedMasksThatAllowWhatWasTaken) {
  EXPECT_TRUE(ValidateSegment(MaskedSegment(), MaskedSpec(), 128).ok());
  Segment s = MaskedSegment();
  s.action_masks = at::Tensor();
  EXPECT_THAT(ValidateSegment(s, MaskedSpec(), 128).message(),
              HasSubstr("action_masks is missing"));
  s = MaskedSegment();
  s.action_masks = at::ones({4, 3}, at::kBool);
  EXPECT_THAT(ValidateSegment(s, MaskedSpec(), 128).message(),
              HasSubstr("action_masks has shape [4, 3], expected [4, 4]"));
  s = MaskedSegment();
  s.action_masks = at::ones({4, 4}, at::kByte);
  EXPECT_THAT(ValidateSegment(s, MaskedSpec(), 128).message(),
              HasSubstr("action_masks has dtype Byte, expected Bool"));
  s = MaskedSegment();
  s.action_masks[2].fill_(false);
  EXPECT_THAT(ValidateSegment(s, MaskedSpec(), 128).message(),
              HasSubstr("action_masks is all zero at step 2"));
  s = MaskedSegment();
  s.actions[1][0] = 3.0f;  // legal at step 0 only
  EXPECT_THAT(ValidateSegment(s, MaskedSpec(), 128).message(),
              HasSubstr("actions holds 3 at step 1, which that step's action "
                        "mask makes illegal"));
  // A run without masks takes none.
  EnvSpec unmasked = MaskedSpec();
  unmasked.action_masks = false;
  EXPECT_THAT(ValidateSegment(MaskedSegment(), unmasked, 128).message(),
              HasSubstr("action_masks is set, but this run's actions "
                        "(discrete:4) take no masks"));
}

// MultiDiscrete: one index per head in its range, and with masks a legal
// choice in every head.
TEST(SegmentTest, MultiDiscreteActionsAreCheckedHeadByHead) {
  EnvSpec spec = MaskedSpec();
  spec.action_nvec = {2, 3};
  spec.action_size = 5;
  Segment s = ValidSegment();
  s.actions = at::tensor({0, 2, 1, 0, 1, 1, 0, 2}, at::kFloat).reshape({4, 2});
  s.action_masks = at::ones({4, 5}, at::kBool);
  EXPECT_TRUE(ValidateSegment(s, spec, 128).ok())
      << ValidateSegment(s, spec, 128);
  s.actions[2][1] = 3.0f;
  EXPECT_THAT(ValidateSegment(s, spec, 128).message(),
              HasSubstr("not action indices in [0, 2), [0, 3)"));
  s.actions[2][1] = 1.0f;
  s.action_masks[3][4] = false;  // step 3 took 2 in head 1
  EXPECT_THAT(ValidateSegment(s, spec, 128).message(),
              HasSubstr("actions holds 2 at step 3 (value 1), which that "
                        "step's action mask makes illegal"));
  s.action_masks[1].slice(0, 0, 2).fill_(false);
  EXPECT_THAT(ValidateSegment(s, spec, 128).message(),
              HasSubstr("action_masks is all zero at step 1 (value 0)"));
}

TEST(SegmentTest, EveryDefectIsNamed) {
  Segment s = ValidSegment();
  s.observations = at::zeros({4, 3});
  EXPECT_THAT(ValidateSegment(s, Spec(), 128).message(),
              HasSubstr("observations has shape [4, 3], expected [5, 3]"));
  s = ValidSegment();
  s.actions = at::zeros({4, 2}, at::kDouble);
  EXPECT_THAT(ValidateSegment(s, Spec(), 128).message(),
              HasSubstr("actions has dtype Double"));
  s = ValidSegment();
  s.rewards[1] = NAN;
  EXPECT_THAT(ValidateSegment(s, Spec(), 128).message(),
              HasSubstr("rewards holds non-finite"));
  s = ValidSegment();
  s.final_observations = at::zeros({0, 3});
  EXPECT_THAT(
      ValidateSegment(s, Spec(), 128).message(),
      HasSubstr("final_observations has shape [0, 3], expected [1, 3]"));
  s = ValidSegment();
  s.terminated[2] = true;
  EXPECT_THAT(ValidateSegment(s, Spec(), 128).message(),
              HasSubstr("both terminated and truncated"));
  s = ValidSegment();
  s.behaviour_log_probs = at::Tensor();
  EXPECT_THAT(ValidateSegment(s, Spec(), 128).message(),
              HasSubstr("behaviour_log_probs is missing"));
  EXPECT_THAT(ValidateSegment(ValidSegment(), Spec(), 3).message(),
              HasSubstr("4 steps, expected 1..3"));
  EnvSpec discrete = Spec();
  discrete.discrete = true;
  discrete.action_size = 2;
  s = ValidSegment();
  s.actions = at::zeros({4, 1});
  s.actions[3][0] = 2.0;
  EXPECT_THAT(ValidateSegment(s, discrete, 128).message(),
              HasSubstr("not action indices in [0, 2)"));
}

TEST(SegmentTest, ValuesBeyondTheLimitsAreNamed) {
  ValueLimits limits;
  limits.max_abs_observation = 100;
  limits.max_abs_action = 10;
  limits.max_abs_reward = 5;
  limits.max_abs_log_prob = 50;
  ASSERT_TRUE(limits.Validate().ok());
  EXPECT_TRUE(ValidateSegment(ValidSegment(), Spec(), 128, limits).ok());
  struct Case {
    std::function<void(Segment&)> change;
    std::string message;
  };
  const std::vector<Case> cases = {
      {[](Segment& s) { s.observations[2][1] = -101; },
       "observations holds -101 at element 7, beyond the limit of +-100"},
      {[](Segment& s) { s.final_observations[0][0] = 1e3; },
       "final_observations holds 1000 at element 0"},
      {[](Segment& s) { s.actions[0][1] = 11; },
       "actions holds 11 at element 1, beyond the limit of +-10"},
      {[](Segment& s) { s.rewards[3] = 3e38f; },
       "rewards holds 3e+38 at element 3, beyond the limit of +-5"},
      {[](Segment& s) { s.behaviour_log_probs[1] = -3e38f; },
       "behaviour_log_probs holds -3e+38 at element 1"},
  };
  for (const Case& c : cases) {
    Segment s = ValidSegment();
    c.change(s);
    EXPECT_THAT(ValidateSegment(s, Spec(), 128, limits).message(),
                HasSubstr(c.message));
  }
  // The default limits are generous but finite: 3e38 is refused there too.
  Segment poisoned = ValidSegment();
  poisoned.rewards[0] = 3e38f;
  EXPECT_THAT(ValidateSegment(poisoned, Spec(), 128).message(),
              HasSubstr("beyond the limit of +-1e+06"));
  limits.max_abs_reward = 0;
  EXPECT_THAT(limits.Validate().message(),
              HasSubstr("max_abs_reward must be > 0"));
}

TEST(SegmentTest, ByteObservationsAreBytesWithinTheSpecsHigh) {
  EnvSpec spec = Spec();
  spec.observation_shape = {3, 1, 1};
  spec.observation_high = 1;
  Segment s = ValidSegment();
  s.observations = at::ones({5, 3}, at::kByte);
  s.final_observations = at::zeros({1, 3}, at::kByte);
  EXPECT_TRUE(ValidateSegment(s, spec, 128).ok())
      << ValidateSegment(s, spec, 128);
  // Float observations where the spec says bytes, and the other way round.
  EXPECT_EQ(ValidateSegment(ValidSegment(), spec, 128).message(),
            "segment field observations has dtype Float, expected Byte");
  EXPECT_EQ(ValidateSegment(s, Spec(), 128).message(),
            "segment field observations has dtype Byte, expected Float");
  // Tensors share storage when a Segment is copied: change clones only.
  Segment above = s;
  above.observations = s.observations.clone();
  above.observations[3][2] = 2;
  EXPECT_EQ(ValidateSegment(above, spec, 128).message(),
            "segment field observations holds 2 at element 11, above the "
            "env's observation_high of 1");
  above = s;
  above.final_observations = s.final_observations.clone();
  above.final_observations[0][0] = 255;
  EXPECT_THAT(ValidateSegment(above, spec, 128).message(),
              HasSubstr("final_observations holds 255 at element 0"));
}

TEST(SegmentTest, EpisodesMustMatchTheEpisodeEnds) {
  struct Case {
    std::function<void(Segment&)> change;
    std::string message;
  };
  // ValidSegment ends one episode, by truncation at step 2.
  const std::vector<Case> cases = {
      {[](Segment& s) {
         s.episode_returns.clear();
         s.episode_lengths.clear();
       },
       "reports 0 episodes but ends one at step 2"},
      {[](Segment& s) {
         s.episode_returns.assign(12600000, 1.0);
         s.episode_lengths.assign(12600000, 1);
       },
       "reports 12600000 episodes but ends 1"},
      {[](Segment& s) { s.episode_lengths.push_back(1); },
       "1 episode returns but 2 episode lengths"},
      {[](Segment& s) { s.episode_returns[0] = NAN; },
       "episode_returns[0] is nan"},
      {[](Segment& s) { s.episode_returns[0] = 1e300; },
       "episode_returns[0] is 1e+300"},
      {[](Segment& s) { s.episode_lengths[0] = 0; },
       "episode_lengths[0] is 0 for the episode ending at step 2"},
      // The spec's time limit bounds every episode.
      {[](Segment& s) { s.episode_lengths[0] = 1001; },
       "episode_lengths[0] is 1001"},
      // Step 0's place in its episode: within the spec's time limit.
      {[](Segment& s) { s.first_episode_step = -1; },
       "segment field first_episode_step is -1, expected 0..999"},
      {[](Segment& s) { s.first_episode_step = 1000; },
       "segment field first_episode_step is 1000, expected 0..999"},
      // A second end: that episode lies wholly inside the segment.
      {[](Segment& s) {
         s.terminated[3] = true;
         s.episode_returns.push_back(1.0);
         s.episode_lengths.push_back(2);
       },
       "episode_lengths[1] is 2 for the episode ending at step 3, expected "
       "1..1"},
  };
  for (const Case& c : cases) {
    Segment s = ValidSegment();
    c.change(s);
    EXPECT_THAT(ValidateSegment(s, Spec(), 128).message(),
                HasSubstr(c.message));
  }
  Segment two = ValidSegment();
  two.terminated[3] = true;
  two.episode_returns.push_back(1.0);
  two.episode_lengths.push_back(1);
  two.first_episode_step = 999;
  EXPECT_TRUE(ValidateSegment(two, Spec(), 128).ok());
}

TEST(SegmentTest, ScalarRewardsAreRefusedNotThrown) {
  Segment s = ValidSegment();
  s.rewards = at::ones({});
  EXPECT_EQ(s.steps(), 0);
  EXPECT_THAT(ValidateSegment(s, Spec(), 128).message(),
              HasSubstr("0 steps, expected 1..128"));
}

// A recurrent run's segments carry the core's start state: of the run's
// size, finite, in whole segments; a feed-forward run's carry none.
TEST(SegmentTest, ACoreStateIsCheckedAgainstTheRun) {
  const ValueLimits limits;
  Segment s = ValidSegment();
  EXPECT_THAT(ValidateSegment(s, Spec(), 4, limits, 6).message(),
              HasSubstr("core_state is missing: this run's policy is "
                        "recurrent (a state of 6 floats"));
  s.core_state = at::zeros({6});
  EXPECT_TRUE(ValidateSegment(s, Spec(), 4, limits, 6).ok());
  EXPECT_THAT(ValidateSegment(s, Spec(), 4).message(),
              HasSubstr("core_state is set, but this run's policy has no "
                        "recurrent core"));
  EXPECT_THAT(ValidateSegment(s, Spec(), 8, limits, 6).message(),
              HasSubstr("segment has 4 steps; a recurrent run takes whole "
                        "segments of 8"));
  s.core_state = at::zeros({5});
  EXPECT_THAT(ValidateSegment(s, Spec(), 4, limits, 6).message(),
              HasSubstr("core_state has shape [5], expected [6]"));
  s.core_state = at::zeros({6});
  s.core_state[2] = std::nanf("");
  EXPECT_THAT(ValidateSegment(s, Spec(), 4, limits, 6).message(),
              HasSubstr("core_state holds non-finite values"));
  s.core_state = at::zeros({6}, at::kDouble);
  EXPECT_THAT(ValidateSegment(s, Spec(), 4, limits, 6).message(),
              HasSubstr("core_state has dtype Double, expected Float"));
}

TEST(SegmentQueueTest, BoundedFifoThatCloses) {
  SegmentQueue queue(2);
  for (int64_t i = 0; i < 2; ++i) {
    Segment s = ValidSegment();
    s.sequence = i;
    ASSERT_TRUE(queue.Send(std::move(s)).ok());
  }
  EXPECT_EQ(queue.size(), 2u);
  // A third Send blocks until a Receive makes room.
  std::thread producer([&] {
    Segment s = ValidSegment();
    s.sequence = 2;
    EXPECT_TRUE(queue.Send(std::move(s)).ok());
  });
  for (int64_t i = 0; i < 3; ++i) {
    absl::StatusOr<Segment> s = queue.Receive();
    ASSERT_TRUE(s.ok());
    EXPECT_EQ(s->sequence, i);
  }
  producer.join();
  queue.Close();
  EXPECT_EQ(queue.Receive().status().code(), absl::StatusCode::kCancelled);
  EXPECT_EQ(queue.Send(ValidSegment()).code(), absl::StatusCode::kCancelled);
}

}  // namespace
}  // namespace vantage
