// A test that fails if nothing is learned: a random policy keeps the
// InvertedPendulum up for about 5 steps, the maximum return is 1000.

#include <ATen/Parallel.h>

#include <cmath>

#include "deploy/local_training.h"
#include "gtest/gtest.h"

namespace vantage {
namespace {

TEST(PpoLearningTest, MaxAbsRho04BalancesTheInvertedPendulum) {
  at::set_num_threads(1);
  LocalTrainingConfig config;
  config.env = "InvertedPendulum";
  config.total_env_steps = 300000;
  config.seed = 1;
  config.learner.horizon = 2048;
  config.learner.advantage.statistic = *ParseStatistic("maxabs");
  config.learner.advantage.rho = 0.4;
  double best = 0.0;
  double last = 0.0;
  const absl::Status status =
      RunLocalTraining(config, [&](const UpdateStats& stats, double mean) {
        if (!std::isnan(mean)) {
          last = mean;
          best = std::max(best, mean);
        }
        EXPECT_NEAR(stats.biased_fraction, 0.4, 0.05);
      });
  ASSERT_TRUE(status.ok()) << status;
  std::printf("best mean return %.1f, last %.1f\n", best, last);
  EXPECT_GE(best, 800.0);
}

}  // namespace
}  // namespace vantage
