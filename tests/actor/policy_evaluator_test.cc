#include "actor/policy_evaluator.h"

#include <ATen/Parallel.h>
#include <torch/torch.h>

#include <string>

#include "actor/envs/env_registry.h"
#include "common/nn/networks.h"
#include "common/nn/policy_weights.h"
#include "common/nn/running_mean_std.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace vantage {
namespace {

using ::testing::HasSubstr;

ActorConfig Pendulum(Core core = Core::kNone) {
  ActorConfig config;
  config.env = "InvertedPendulum";
  config.seed = 3;
  config.network.hidden = {16};
  config.network.core = core;
  config.network.core_size = 8;
  return config;
}

// Version `version` of a freshly initialised policy of `config`'s network.
PolicyWeights FreshWeights(const ActorConfig& config, int64_t version,
                           uint64_t init_seed) {
  torch::manual_seed(init_seed);
  absl::StatusOr<std::unique_ptr<Environment>> env =
      MakeEnvironment(config.env, config.env_options);
  EXPECT_TRUE(env.ok()) << env.status();
  PolicyNetwork policy((*env)->spec(), config.network);
  RunningMeanStd normalizer((*env)->spec().observation_size);
  return ExportPolicyWeights(*policy, normalizer, version);
}

// The same version plays the same episodes every time (their seeds are the
// evaluator's, the actions the policy's mean), each to its end: on
// InvertedPendulum a return is its length (a reward of 1 per step).
TEST(PolicyEvaluatorTest, AVersionPlaysTheSameEpisodesEveryTime) {
  at::set_num_threads(1);
  for (Core core : {Core::kNone, Core::kGru}) {
    const ActorConfig config = Pendulum(core);
    absl::StatusOr<std::unique_ptr<PolicyEvaluator>> evaluator =
        PolicyEvaluator::Create(config, 4);
    ASSERT_TRUE(evaluator.ok()) << evaluator.status();
    const PolicyWeights weights = FreshWeights(config, 7, 1);
    absl::StatusOr<PolicyEvaluation> first = (*evaluator)->Evaluate(weights);
    ASSERT_TRUE(first.ok()) << first.status();
    EXPECT_EQ(first->version, 7);
    ASSERT_EQ(first->returns.size(), 4u);
    ASSERT_EQ(first->lengths.size(), 4u);
    for (size_t i = 0; i < 4; ++i) {
      EXPECT_GE(first->lengths[i], 1);
      EXPECT_LE(first->lengths[i], 1000);
      EXPECT_DOUBLE_EQ(first->returns[i], double(first->lengths[i]));
    }
    // Four episodes from four seeds: not all the same start.
    EXPECT_FALSE(first->lengths[0] == first->lengths[1] &&
                 first->lengths[1] == first->lengths[2] &&
                 first->lengths[2] == first->lengths[3]);
    absl::StatusOr<PolicyEvaluation> again = (*evaluator)->Evaluate(weights);
    ASSERT_TRUE(again.ok());
    EXPECT_EQ(again->returns, first->returns);
    // Another policy acts otherwise on the same episodes (a fresh policy's
    // mean is near 0 whatever its seed: this one pushes hard).
    PolicyWeights pushing = FreshWeights(config, 8, 2);
    for (at::Tensor& parameter : pushing.parameters) parameter.mul_(50.0);
    absl::StatusOr<PolicyEvaluation> other = (*evaluator)->Evaluate(pushing);
    ASSERT_TRUE(other.ok());
    EXPECT_NE(other->returns, first->returns);
  }
}

// Another run seed plays other episodes.
TEST(PolicyEvaluatorTest, TheRunSeedDecidesTheEpisodes) {
  ActorConfig config = Pendulum();
  const PolicyWeights weights = FreshWeights(config, 1, 1);
  auto a = PolicyEvaluator::Create(config, 6);
  config.seed = 4;
  auto b = PolicyEvaluator::Create(config, 6);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_NE((*a)->Evaluate(weights)->lengths, (*b)->Evaluate(weights)->lengths);
}

TEST(PolicyEvaluatorTest, RefusesWhatItCannotPlay) {
  EXPECT_THAT(
      std::string(PolicyEvaluator::Create(Pendulum(), 0).status().message()),
      HasSubstr(">= 1 episode"));
  ActorConfig unknown = Pendulum();
  unknown.env = "NoSuchEnv";
  EXPECT_THAT(
      std::string(PolicyEvaluator::Create(unknown, 1).status().message()),
      HasSubstr("NoSuchEnv"));
  // Weights of another network are refused, not played.
  ActorConfig wider = Pendulum();
  wider.network.hidden = {32};
  auto evaluator = PolicyEvaluator::Create(Pendulum(), 1);
  ASSERT_TRUE(evaluator.ok());
  EXPECT_FALSE((*evaluator)->Evaluate(FreshWeights(wider, 1, 1)).ok());
}

}  // namespace
}  // namespace vantage
