#include "learner/ingest/rollout_stitcher.h"

#include <ATen/ATen.h>

#include <vector>

#include "gtest/gtest.h"

namespace vantage {
namespace {

// One long stream of `total` steps (obs 2, act 1) with known values, cut
// into segments of the given lengths: step t has reward t, observation
// (t, -t), truncation every 7th step with final observation (100 + t, 0),
// so observation t is step t % 7 of its episode.
struct Stream {
  std::vector<Segment> segments;
  at::Tensor observations, rewards, truncated, finals;
};

Stream MakeStream(const std::vector<int64_t>& lengths, int64_t actor = 0,
                  int64_t slot = 0) {
  int64_t total = 0;
  for (int64_t l : lengths) total += l;
  Stream stream;
  stream.observations = at::empty({total + 1, 2});
  for (int64_t t = 0; t <= total; ++t) {
    stream.observations[t][0] = static_cast<float>(t);
    stream.observations[t][1] = static_cast<float>(-t);
  }
  stream.rewards = at::arange(total, at::kFloat);
  stream.truncated = (at::arange(total) % 7) == 6;
  std::vector<at::Tensor> finals;
  for (int64_t t = 0; t < total; ++t) {
    if (t % 7 == 6) {
      finals.push_back(at::tensor({100.0f + t, 0.0f}));
    }
  }
  stream.finals = at::stack(finals);
  int64_t begin = 0;
  int64_t sequence = 0;
  int64_t finals_before = 0;
  for (int64_t l : lengths) {
    Segment s;
    s.actor_id = actor;
    s.env_slot = slot;
    s.sequence = sequence++;
    s.policy_version = sequence;
    s.observations = stream.observations.slice(0, begin, begin + l + 1).clone();
    s.actions = s.rewards = stream.rewards.slice(0, begin, begin + l).clone();
    s.actions = s.actions.unsqueeze(1);
    s.terminated = at::zeros({l}, at::kBool);
    s.truncated = stream.truncated.slice(0, begin, begin + l).clone();
    const int64_t k = s.truncated.sum().item<int64_t>();
    s.final_observations =
        stream.finals.slice(0, finals_before, finals_before + k).clone();
    finals_before += k;
    s.behaviour_log_probs = -s.rewards;
    s.first_episode_step = begin % 7;
    stream.segments.push_back(s);
    begin += l;
  }
  return stream;
}

TEST(RolloutStitcherTest, StitchesAcrossSegmentBoundaries) {
  const Stream stream = MakeStream({5, 5, 5, 5, 5, 5});
  RolloutStitcher stitcher(8);
  for (const Segment& s : stream.segments) ASSERT_TRUE(stitcher.Add(s).ok());
  const std::vector<Rollout> rollouts = stitcher.TakeReady();
  ASSERT_EQ(rollouts.size(), 3u);  // 30 steps: 3 x 8, 6 left
  EXPECT_EQ(stitcher.buffered_steps(), 6);
  int64_t finals_before = 0;
  for (int64_t r = 0; r < 3; ++r) {
    const Rollout& rollout = rollouts[r];
    const int64_t b = 8 * r;
    EXPECT_TRUE(
        at::equal(rollout.observations, stream.observations.slice(0, b, b + 9)))
        << r;
    EXPECT_TRUE(at::equal(rollout.rewards, stream.rewards.slice(0, b, b + 8)));
    EXPECT_TRUE(
        at::equal(rollout.truncated, stream.truncated.slice(0, b, b + 8)));
    const int64_t k = rollout.truncated.sum().item<int64_t>();
    EXPECT_TRUE(
        at::equal(rollout.final_observations,
                  stream.finals.slice(0, finals_before, finals_before + k)))
        << r;
    finals_before += k;
    EXPECT_TRUE(at::equal(rollout.behaviour_log_probs, -rollout.rewards));
    // Steps 8..15 come from segments 1, 2 and 3 (versions 2, 3, 4).
    EXPECT_EQ(rollout.policy_versions[0].item<int64_t>(), b / 5 + 1);
    EXPECT_EQ(rollout.policy_versions[7].item<int64_t>(), (b + 7) / 5 + 1);
  }
  EXPECT_EQ(stitcher.stats().rollouts, 3);
}

// Each observation's step within its episode, from each segment's first
// and the episode ends after it, across segment and rollout boundaries.
TEST(RolloutStitcherTest, RolloutsSayWhichStepOfItsEpisodeEachObservationIs) {
  const Stream stream = MakeStream({5, 3, 9, 4, 3});
  RolloutStitcher stitcher(6);
  for (const Segment& s : stream.segments) ASSERT_TRUE(stitcher.Add(s).ok());
  const std::vector<Rollout> rollouts = stitcher.TakeReady();
  ASSERT_EQ(rollouts.size(), 4u);
  for (int64_t r = 0; r < 4; ++r) {
    const at::Tensor expected = at::arange(6 * r, 6 * r + 7, at::kLong) % 7;
    EXPECT_TRUE(at::equal(rollouts[r].episode_steps, expected))
        << r << ": " << rollouts[r].episode_steps;
  }
}

TEST(RolloutStitcherTest, LongSegmentsYieldSeveralRollouts) {
  const Stream stream = MakeStream({20});
  RolloutStitcher stitcher(6);
  ASSERT_TRUE(stitcher.Add(stream.segments[0]).ok());
  const std::vector<Rollout> rollouts = stitcher.TakeReady();
  ASSERT_EQ(rollouts.size(), 3u);
  EXPECT_TRUE(at::equal(rollouts[2].observations,
                        stream.observations.slice(0, 12, 19)));
  EXPECT_EQ(stitcher.buffered_steps(), 2);
}

TEST(RolloutStitcherTest, NothingIsStitchedAcrossAGap) {
  Stream stream = MakeStream({5, 5, 5, 5});
  RolloutStitcher stitcher(8);
  ASSERT_TRUE(stitcher.Add(stream.segments[0]).ok());
  // Segment 1 is lost (an actor restarted): 2 follows 0.
  ASSERT_TRUE(stitcher.Add(stream.segments[2]).ok());
  EXPECT_EQ(stitcher.stats().gaps, 1);
  EXPECT_EQ(stitcher.stats().dropped_steps, 5);
  ASSERT_TRUE(stitcher.Add(stream.segments[3]).ok());
  const std::vector<Rollout> rollouts = stitcher.TakeReady();
  ASSERT_EQ(rollouts.size(), 1u);
  // The rollout starts at segment 2 (stream step 10), never at step 0..4.
  EXPECT_TRUE(at::equal(rollouts[0].observations,
                        stream.observations.slice(0, 10, 19)));
  // A repeated or older segment is refused and changes nothing.
  EXPECT_EQ(stitcher.Add(stream.segments[3]).code(),
            absl::StatusCode::kFailedPrecondition);
  EXPECT_EQ(stitcher.stats().stale_segments, 1);
  EXPECT_EQ(stitcher.buffered_steps(), 2);
}

// Segment i of MakeStream was acted by version i + 1. Dropping versions
// below 3 removes the first two segments' steps; the stream goes on from
// the third, so the next rollout starts at step 6.
TEST(RolloutStitcherTest, DropsStepsOfStalePolicyVersions) {
  const Stream stream = MakeStream({3, 3, 3, 7});
  RolloutStitcher stitcher(10);
  for (int i = 0; i < 3; ++i)
    ASSERT_TRUE(stitcher.Add(stream.segments[i]).ok());
  EXPECT_EQ(stitcher.DropStepsOlderThan(3), 6);
  EXPECT_EQ(stitcher.buffered_steps(), 3);
  EXPECT_EQ(stitcher.stats().stale_steps, 6);
  EXPECT_EQ(stitcher.DropStepsOlderThan(3), 0);
  ASSERT_TRUE(stitcher.Add(stream.segments[3]).ok());
  const std::vector<Rollout> rollouts = stitcher.TakeReady();
  ASSERT_EQ(rollouts.size(), 1u);
  EXPECT_TRUE(
      at::equal(rollouts[0].observations, stream.observations.slice(0, 6, 17)));
  EXPECT_EQ(rollouts[0].policy_versions.min().item<int64_t>(), 3);
}

TEST(RolloutStitcherTest, StreamsStayApart) {
  const Stream a = MakeStream({4, 4}, /*actor=*/0, /*slot=*/1);
  const Stream b = MakeStream({4, 4}, /*actor=*/1, /*slot=*/1);
  RolloutStitcher stitcher(8);
  ASSERT_TRUE(stitcher.Add(a.segments[0]).ok());
  ASSERT_TRUE(stitcher.Add(b.segments[0]).ok());
  ASSERT_TRUE(stitcher.Add(b.segments[1]).ok());
  ASSERT_TRUE(stitcher.Add(a.segments[1]).ok());
  const std::vector<Rollout> rollouts = stitcher.TakeReady();
  ASSERT_EQ(rollouts.size(), 2u);
  EXPECT_EQ(rollouts[0].actor_id, 1);
  EXPECT_EQ(rollouts[1].actor_id, 0);
  EXPECT_EQ(rollouts[1].env_slot, 1);
}

TEST(RolloutStitcherTest, EvictionDropsTheLeastRecentlyFedStreams) {
  RolloutStitcher stitcher(32);
  // Three partial streams of 7, 8 and 9 steps, fed in the order 0, 1, 2.
  for (int64_t slot = 0; slot < 3; ++slot) {
    const Stream s = MakeStream({7 + slot}, /*actor=*/7, slot);
    ASSERT_TRUE(stitcher.Add(s.segments[0]).ok());
  }
  EXPECT_EQ(stitcher.buffered_steps(), 24);
  // Room for 12 with slot 0 spared: slot 1 (the older) goes, then slot 2.
  EXPECT_EQ(stitcher.EvictDownTo(12, /*actor_id=*/7, /*env_slot=*/0), 8 + 9);
  EXPECT_EQ(stitcher.buffered_steps(), 7);
  EXPECT_EQ(stitcher.stats().evicted_steps, 17);
  // The spared stream is never evicted, even when alone over budget.
  EXPECT_EQ(stitcher.EvictDownTo(0, 7, 0), 0);
  EXPECT_EQ(stitcher.buffered_steps(), 7);
  // An evicted stream starts afresh with its next segment.
  const Stream again = MakeStream({8, 32}, 7, 1);
  ASSERT_TRUE(stitcher.Add(again.segments[1]).ok());
  EXPECT_EQ(stitcher.TakeReady().size(), 1u);
  EXPECT_EQ(stitcher.buffered_steps(), 7);
}

TEST(RolloutStitcherTest, ForgettingAnActorFreesItsStreams) {
  RolloutStitcher stitcher(16);
  for (int64_t actor : {3, 4}) {
    for (int64_t slot = 0; slot < 2; ++slot) {
      ASSERT_TRUE(stitcher.Add(MakeStream({7}, actor, slot).segments[0]).ok());
    }
  }
  EXPECT_EQ(stitcher.stream_count(), 4u);
  EXPECT_EQ(stitcher.ForgetActor(3), 14);
  EXPECT_EQ(stitcher.stream_count(), 2u);
  EXPECT_EQ(stitcher.buffered_steps(), 14);
  EXPECT_EQ(stitcher.ForgetActor(9), 0);
}

}  // namespace
}  // namespace vantage
