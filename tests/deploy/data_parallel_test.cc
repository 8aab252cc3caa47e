// `vantage train --learners=2`: two learner processes averaging gradients
// over c10d/Gloo, each serving one of the actors, on loopback.

#include <signal.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/deploy/cli/run_vantage.h"
#include "tests/fakes/learner_process.h"
#include "tests/fakes/run_files.h"

namespace vantage {
namespace {

using ::testing::HasSubstr;

// progress.csv's mean_return column (the fifth).
std::vector<double> MeanReturns(const std::string& run_dir) {
  std::vector<double> returns;
  const std::vector<std::string> rows = DeterministicProgress(run_dir);
  for (size_t i = 1; i < rows.size(); ++i) {
    const std::vector<std::string> cells = absl::StrSplit(rows[i], ',');
    double value = std::nan("");
    if (cells.size() > 4 && absl::SimpleAtod(cells[4], &value)) {
      returns.push_back(value);
    }
  }
  return returns;
}

// The learning tests' bar for PPO with maxabs at rho 0.4 (>= 800 within
// 300k steps, a random policy gets 5-8), reached with the global batch of
// the local test (2048 steps: 1024 from each learner's actor). A sync run
// with one actor per learner is deterministic.
TEST(DataParallelTest, TwoLearnersBalanceTheInvertedPendulum) {
  const std::string run = FreshDirectory("two_learners_learn");
  const Outcome train = RunVantage(
      "train --learners=2 --actors=2 --envs_per_actor=1 --horizon=1024 "
      "--env=InvertedPendulum --algo=ppo --estimator=maxabs --rho=0.4 "
      "--steps=300000 --seed=1 --run_dir=" +
      run);
  ASSERT_EQ(train.exit_code, 0) << train.err;
  EXPECT_THAT(train.err, HasSubstr("2 learners on ports"));
  const std::vector<double> returns = MeanReturns(run);
  ASSERT_FALSE(returns.empty());
  double best = 0.0;
  for (double r : returns) {
    if (!std::isnan(r)) best = std::max(best, r);
  }
  std::printf("two learners: best mean return %.1f, last %.1f\n", best,
              returns.back());
  EXPECT_GE(best, 800.0);
}

// One replica killed with SIGKILL mid-run: the other cannot go on alone
// (its next all-reduce fails), so the launcher stops it and restarts both
// from the run's last checkpoint; the actors reconnect and the run ends
// with one progress row per version, as if nothing had happened.
TEST(DataParallelTest, AKilledReplicaRestartsEveryLearner) {
  const std::string run = FreshDirectory("replica_killed");
  const std::string err = TempPath("replicas.err");
  const int train = StartVantage(
      "train --learners=2 --actors=2 --envs_per_actor=1 --steps=8192 "
      "--horizon=512 --checkpoint_every=2 --seed=4 --run_dir=" +
          run,
      TempPath("replicas.out"), err);
  for (int i = 0; i < 1200 && DeterministicProgress(run).size() < 1 + 3; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ASSERT_GE(DeterministicProgress(run).size(), 1u + 3) << ReadFile(err);
  ASSERT_EQ(ChildrenRunning(train, " learner ").size(), 2u);
  const std::vector<int> second = ChildrenRunning(train, "--rank=1");
  ASSERT_EQ(second.size(), 1u);
  kill(second[0], SIGKILL);
  EXPECT_EQ(WaitVantage(train, 240), 0) << ReadFile(err);
  const std::string log = ReadFile(err);
  EXPECT_THAT(log, HasSubstr("learner 1 ended (signal 9); resuming every "
                             "learner from the run's last checkpoint"));
  EXPECT_THAT(log, HasSubstr("learner: resuming "));
  const std::vector<std::string> rows = DeterministicProgress(run);
  ASSERT_EQ(rows.size(), 1u + 8) << absl::StrJoin(rows, "\n");
  for (int v = 1; v <= 8; ++v) {
    EXPECT_THAT(rows[v], ::testing::StartsWith(
                             absl::StrCat(1024 * v, ",", v, ",", v, ",")));
  }
  EXPECT_TRUE(ChildrenRunning(train, "vantage").empty());
}

TEST(DataParallelTest, LearnersMustSplitTheActorsEvenly) {
  const Outcome train =
      RunVantage("train --learners=2 --actors=3 --steps=1000");
  EXPECT_EQ(train.exit_code, 2);
  EXPECT_THAT(train.err, HasSubstr("--learners must divide --actors (3)"));
}

}  // namespace
}  // namespace vantage
