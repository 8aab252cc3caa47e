#include "common/rollout/segment.h"

#include <ATen/ATen.h>

#include <thread>

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
