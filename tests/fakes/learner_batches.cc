#include "tests/fakes/learner_batches.h"

#include <ATen/ATen.h>

#include "absl/strings/match.h"
#include "gtest/gtest.h"
#include "learner/algorithms/ppo/ppo_config.h"

namespace vantage {

NetworkConfig TestNetwork(const std::string& algorithm) {
  NetworkConfig network;
  if (absl::EndsWith(algorithm, "_gru")) {
    network.core = Core::kGru;
    network.core_size = 16;
    network.seq_len = 16;
  }
  return network;
}

LearnerConfig TestLearnerConfig(const EnvSpec& spec, const std::string& name) {
  const std::string algorithm = name.substr(0, name.find('_'));
  LearnerConfig config;
  config.spec = spec;
  config.network = TestNetwork(name);
  // A2C's rollouts are 5n steps.
  config.horizon = algorithm == "a2c" ? 60 : kTestHorizon;
  config.rollouts_per_batch = kTestEnvs;
  config.max_segment_steps = kTestHorizon;
  config.total_env_steps = 10 * kTestHorizon * kTestEnvs;
  config.seed = 3;
  config.scale_rewards = true;
  config.advantage.statistic = *ParseStatistic("maxabs");
  config.advantage.rho = 0.5;
  config.algorithm.name = algorithm;
  config.algorithm.Mutable<PpoConfig>().minibatches = 4;
  config.algorithm.Mutable<PpoConfig>().epochs = 2;
  return config;
}

std::unique_ptr<ActorCore> MakeTestActor(int64_t segment_length,
                                         const std::string& env,
                                         const NetworkConfig& network) {
  ActorConfig config;
  config.network = network;
  config.env = env;
  config.num_envs = kTestEnvs;
  config.segment_length = segment_length;
  config.seed = 9;
  return *ActorCore::Create(config);
}

std::vector<Segment> ActOneBatch(ActorCore& actor, LearnerCore& learner) {
  EXPECT_TRUE(actor.SetWeights(learner.CurrentWeights()).ok());
  SegmentQueue queue(kTestEnvs);
  EXPECT_TRUE(actor.CollectSegments(queue).ok());
  queue.Close();
  std::vector<Segment> segments;
  for (absl::StatusOr<Segment> s = queue.Receive(); s.ok();
       s = queue.Receive()) {
    segments.push_back(*std::move(s));
  }
  return segments;
}

UpdateStats UpdateWith(LearnerCore& learner,
                       const std::vector<Segment>& batch) {
  SegmentQueue queue(batch.size());
  for (const Segment& s : batch) EXPECT_TRUE(queue.Send(s).ok());
  absl::StatusOr<UpdateStats> stats = learner.RunUpdate(queue);
  EXPECT_TRUE(stats.ok()) << stats.status();
  return *stats;
}

void ExpectSameWeights(LearnerCore& a, LearnerCore& b) {
  const PolicyWeights wa = a.CurrentWeights();
  const PolicyWeights wb = b.CurrentWeights();
  EXPECT_EQ(wa.version, wb.version);
  ASSERT_EQ(wa.parameters.size(), wb.parameters.size());
  for (size_t i = 0; i < wa.parameters.size(); ++i) {
    EXPECT_TRUE(wa.parameters[i].equal(wb.parameters[i])) << "parameter " << i;
  }
  EXPECT_EQ(wa.normalizer_count, wb.normalizer_count);
  EXPECT_TRUE(wa.normalizer_mean.equal(wb.normalizer_mean));
  EXPECT_TRUE(wa.normalizer_var.equal(wb.normalizer_var));
}

}  // namespace vantage
