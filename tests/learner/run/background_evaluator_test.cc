#include "learner/run/background_evaluator.h"

#include <atomic>
#include <chrono>
#include <future>
#include <thread>
#include <vector>

#include "gtest/gtest.h"

namespace vantage {
namespace {

PolicyWeights Version(int64_t version) {
  PolicyWeights weights;
  weights.version = version;
  return weights;
}

// Each evaluation returns its version as its one return, after waiting for
// the test to let it go.
struct GatedEvaluation {
  std::atomic<int> started{0};
  std::promise<void> release;
  std::shared_future<void> gate = release.get_future().share();

  EvaluatePolicy Function() {
    return
        [this](
            const PolicyWeights& weights) -> absl::StatusOr<PolicyEvaluation> {
          ++started;
          gate.wait();
          if (weights.version < 0) return absl::InternalError("env broke");
          PolicyEvaluation evaluation;
          evaluation.version = weights.version;
          evaluation.returns = {double(weights.version)};
          evaluation.lengths = {1};
          return evaluation;
        };
  }
};

void WaitUntil(const std::function<bool()>& condition) {
  for (int i = 0; i < 1000 && !condition(); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ASSERT_TRUE(condition());
}

// While version 2 is evaluated, 4 and 6 arrive: 4 is dropped for 6, and
// the learner collects 2 and 6 in order.
TEST(BackgroundEvaluatorTest, TheNewestWaitingVersionIsEvaluatedNext) {
  GatedEvaluation gated;
  BackgroundEvaluator evaluator(gated.Function());
  evaluator.Submit(Version(2));
  WaitUntil([&] { return gated.started == 1; });
  evaluator.Submit(Version(4));
  evaluator.Submit(Version(6));
  EXPECT_TRUE(evaluator.TakeFinished().empty());
  gated.release.set_value();
  evaluator.Drain();
  const std::vector<PolicyEvaluation> finished = evaluator.TakeFinished();
  ASSERT_EQ(finished.size(), 2u);
  EXPECT_EQ(finished[0].version, 2);
  EXPECT_EQ(finished[1].version, 6);
  EXPECT_EQ(evaluator.skipped(), 1);
  EXPECT_TRUE(evaluator.TakeFinished().empty());
}

TEST(BackgroundEvaluatorTest, AFailedEvaluationIsSaidAndTrainingGoesOn) {
  GatedEvaluation gated;
  gated.release.set_value();
  BackgroundEvaluator evaluator(gated.Function());
  evaluator.Submit(Version(-1));
  evaluator.Drain();
  EXPECT_TRUE(evaluator.TakeFinished().empty());
  evaluator.Submit(Version(3));
  evaluator.Drain();
  const std::vector<PolicyEvaluation> finished = evaluator.TakeFinished();
  ASSERT_EQ(finished.size(), 1u);
  EXPECT_EQ(finished[0].version, 3);
}

TEST(BackgroundEvaluatorTest, StopsAfterTheEvaluationInProgress) {
  GatedEvaluation gated;
  auto evaluator = std::make_unique<BackgroundEvaluator>(gated.Function());
  evaluator->Submit(Version(1));
  WaitUntil([&] { return gated.started == 1; });
  std::thread release([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    gated.release.set_value();
  });
  evaluator.reset();  // returns once version 1 is done
  release.join();
  EXPECT_EQ(gated.started, 1);
}

}  // namespace
}  // namespace vantage
