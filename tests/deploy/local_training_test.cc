#include "deploy/local_training.h"

#include <ATen/Parallel.h>

#include <vector>

#include "gtest/gtest.h"

namespace vantage {
namespace {

std::vector<double> Trace(uint64_t seed) {
  LocalTrainingConfig config;
  config.env = "Hopper";
  config.num_envs = 2;
  config.total_env_steps = 3 * 2 * 256;
  config.seed = seed;
  config.learner.horizon = 256;
  config.learner.ppo.minibatches = 8;
  config.learner.ppo.epochs = 2;
  config.learner.advantage.statistic = *ParseStatistic("max");
  config.learner.advantage.rho = 0.5;
  std::vector<double> trace;
  const absl::Status status =
      RunLocalTraining(config, [&](const UpdateStats& stats, double mean) {
        trace.insert(trace.end(),
                     {stats.ppo.policy_loss, stats.ppo.value_loss,
                      stats.ppo.entropy, stats.ppo.approx_kl,
                      stats.biased_fraction, stats.mean_abs_bias, mean});
      });
  EXPECT_TRUE(status.ok()) << status;
  return trace;
}

// Local mode is deterministic: the same seed repeats every statistic
// exactly, another seed does not.
TEST(LocalTrainingTest, SameSeedSameRun) {
  at::set_num_threads(1);
  const std::vector<double> first = Trace(4);
  ASSERT_EQ(first.size(), 3u * 7);
  EXPECT_EQ(first, Trace(4));
  EXPECT_NE(first, Trace(5));
}

}  // namespace
}  // namespace vantage
