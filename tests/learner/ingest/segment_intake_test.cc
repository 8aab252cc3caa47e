#include "learner/ingest/segment_intake.h"

#include <ATen/ATen.h>

#include <string>
#include <vector>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/fakes/learner_batches.h"

namespace vantage {
namespace {

using ::testing::HasSubstr;

// A queue that says its sender already checked what it holds, as the
// learner's gateway does.
SegmentQueue CheckedQueue() { return SegmentQueue(64, /*checked=*/true); }

class SegmentIntakeTest : public ::testing::Test {
 protected:
  SegmentIntakeTest()
      : actor_(MakeTestActor()),
        config_(TestLearnerConfig(actor_->spec(), "ppo")),
        learner_(*LearnerCore::Create(config_)) {}

  std::vector<Segment> Batch() { return ActOneBatch(*actor_, *learner_); }

  std::unique_ptr<ActorCore> actor_;
  LearnerConfig config_;
  std::unique_ptr<LearnerCore> learner_;
};

TEST_F(SegmentIntakeTest, AnUncheckedSegmentIsCheckedAndRefusedByName) {
  SegmentIntake intake(config_);
  SegmentQueue queue(64);
  std::vector<Segment> batch = Batch();
  Segment bad = batch[0];
  bad.rewards = bad.rewards.clone();
  bad.rewards[0] = std::nanf("");
  ASSERT_TRUE(queue.Send(bad).ok());
  for (Segment& segment : batch) ASSERT_TRUE(queue.Send(segment).ok());
  absl::StatusOr<std::vector<Rollout>> rollouts = intake.NextBatch(queue, 0);
  ASSERT_TRUE(rollouts.ok()) << rollouts.status();
  EXPECT_EQ(rollouts->size(), static_cast<size_t>(config_.rollouts_per_batch));
  EXPECT_EQ(intake.unreported().rejected, 1);
  EXPECT_THAT(intake.TakeFirstRejection(),
              HasSubstr("actor " + std::to_string(bad.actor_id) + " slot " +
                        std::to_string(bad.env_slot) + ": "));
  EXPECT_EQ(intake.TakeFirstRejection(), "");
}

TEST_F(SegmentIntakeTest, AnUnpublishedVersionIsRefusedWithTheGatewaysWords) {
  SegmentIntake intake(config_);
  SegmentQueue queue(64);
  std::vector<Segment> batch = Batch();
  Segment future = batch[0];
  future.policy_version = 7;
  ASSERT_TRUE(queue.Send(future).ok());
  for (Segment& segment : batch) ASSERT_TRUE(queue.Send(segment).ok());
  ASSERT_TRUE(intake.NextBatch(queue, 0).ok());
  EXPECT_THAT(intake.TakeFirstRejection(),
              HasSubstr("segment.policy_version 7 has not been published "
                        "(newest: 0)"));
}

// What the gateway checked is not checked again; staleness still is, since
// a segment can age in the queue.
TEST_F(SegmentIntakeTest, ACheckedSourceIsTrustedButStaleStepsAreDropped) {
  SegmentIntake intake(config_);
  SegmentQueue queue = CheckedQueue();
  std::vector<Segment> batch = Batch();
  for (Segment& segment : batch) ASSERT_TRUE(queue.Send(segment).ok());
  for (Segment& segment : Batch()) {
    segment.policy_version = 1;
    ASSERT_TRUE(queue.Send(segment).ok());
  }
  // At version 1 in sync mode the first batch (version 0) is too old.
  absl::StatusOr<std::vector<Rollout>> rollouts = intake.NextBatch(queue, 1);
  ASSERT_TRUE(rollouts.ok()) << rollouts.status();
  EXPECT_EQ(intake.unreported().stale_segments,
            static_cast<int64_t>(batch.size()));
  for (const Rollout& rollout : *rollouts) {
    EXPECT_EQ(rollout.policy_versions.min().item<int64_t>(), 1);
  }
  intake.ResetCounts();
  EXPECT_EQ(intake.unreported().rejected, 0);
}

TEST(SegmentCheckTest, OnlyTheNewestVersionsTrain) {
  const SegmentCheck sync({}, 64, {}, 0);
  EXPECT_FALSE(sync.TooStale(5, 5));
  EXPECT_TRUE(sync.TooStale(4, 5));
  const SegmentCheck lagged({}, 64, {}, 2);
  EXPECT_FALSE(lagged.TooStale(3, 5));
  EXPECT_TRUE(lagged.TooStale(2, 5));
  const SegmentCheck any({}, 64, {}, -1);
  EXPECT_FALSE(any.TooStale(-100, 5));
  EXPECT_TRUE(SegmentCheck::CheckPublished(5, 5).ok());
  EXPECT_EQ(SegmentCheck::CheckPublished(6, 5).code(),
            absl::StatusCode::kFailedPrecondition);
}

}  // namespace
}  // namespace vantage
