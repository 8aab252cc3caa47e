#include "tests/fuzz/fuzz_fixtures.h"

#include <ATen/ATen.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "common/rollout/segment_queue.h"
#include "learner/algorithms/a2c/a2c_config.h"
#include "learner/algorithms/ppo/ppo_config.h"
#include "learner/checkpoint/checkpoint.h"

namespace vantage {

EnvSpec FuzzContinuousSpec() {
  EnvSpec spec;
  spec.name = "FuzzBox";
  spec.observation_size = 4;
  spec.action_size = 1;
  spec.action_low = {-3.0};
  spec.action_high = {3.0};
  spec.max_episode_steps = 1000;
  spec.control_dt = 0.05;
  return spec;
}

EnvSpec FuzzDiscreteSpec() {
  EnvSpec spec;
  spec.name = "FuzzGrid";
  spec.observation_size = 4;
  spec.discrete = true;
  spec.action_size = 3;
  spec.max_episode_steps = 50;
  return spec;
}

LearnerConfig FuzzLearnerConfig(const std::string& algorithm) {
  LearnerConfig config;
  config.spec = FuzzContinuousSpec();
  config.horizon = 20;
  config.rollouts_per_batch = 2;
  config.max_segment_steps = 20;
  config.total_env_steps = 400;
  config.seed = 5;
  config.scale_rewards = true;
  config.network.hidden = {8};
  config.advantage.ensemble = {1, 4};
  config.advantage.rho = 0.5;
  config.algorithm.name = algorithm;
  config.algorithm.Mutable<PpoConfig>().minibatches = 2;
  config.algorithm.Mutable<PpoConfig>().epochs = 1;
  config.algorithm.Mutable<A2cConfig>().n = 2;
  return config;
}

LearnerConfig FuzzEx2LearnerConfig() {
  LearnerConfig config = FuzzLearnerConfig("ppo");
  Ex2Config ex2;
  ex2.hidden = {4};
  ex2.feature_dim = 2;
  ex2.replay_min = 1;
  ex2.replay_size = 64;
  ex2.first_train_iterations = 3;
  ex2.train_iterations = 2;
  ex2.batch_size = 8;
  config.exploration.ex2 = ex2;
  return config;
}

Segment FuzzSegment(const EnvSpec& spec, int64_t steps, int64_t env_slot,
                    int64_t policy_version, uint64_t seed) {
  at::Generator generator = at::detail::createCPUGenerator(seed);
  const int64_t obs = spec.observation_size;
  Segment segment;
  segment.env_slot = env_slot;
  segment.policy_version = policy_version;
  segment.observations = at::randn({steps + 1, obs}, generator, at::kFloat);
  segment.actions =
      spec.discrete
          ? at::randint(spec.action_size, {steps, 1}, generator, at::kFloat)
          : at::rand({steps, spec.action_size}, generator, at::kFloat) * 2 - 1;
  segment.rewards = at::randn({steps}, generator, at::kFloat);
  segment.terminated = at::zeros({steps}, at::kBool);
  segment.truncated = at::zeros({steps}, at::kBool);
  segment.terminated[0] = true;
  segment.truncated[2] = true;
  segment.final_observations = at::randn({1, obs}, generator, at::kFloat);
  segment.behaviour_log_probs = -at::rand({steps}, generator, at::kFloat) - 0.5;
  const at::Tensor rewards = segment.rewards.to(at::kDouble);
  segment.episode_returns = {rewards[0].item<double>(),
                             rewards.slice(0, 1, 3).sum().item<double>()};
  segment.episode_lengths = {1, 2};
  return segment;
}

absl::StatusOr<std::unique_ptr<LearnerCore>> ReadFuzzCheckpoint(
    const std::string& path) {
  (void)ReadCheckpointExtras(path);
  absl::StatusOr<std::unique_ptr<LearnerCore>> learner =
      ReadCheckpoint(path, FuzzLearnerConfig("ppo"));
  for (const char* algorithm : {"a2c", "trpo"}) {
    if (!learner.ok() &&
        absl::StrContains(learner.status().message(),
                          absl::StrCat("trained with ", algorithm, ","))) {
      learner = ReadCheckpoint(path, FuzzLearnerConfig(algorithm));
    }
  }
  return learner;
}

absl::StatusOr<std::unique_ptr<LearnerCore>> ReadFuzzEx2Checkpoint(
    const std::string& path) {
  (void)ReadCheckpointExtras(path);
  return ReadCheckpoint(path, FuzzEx2LearnerConfig());
}

void CheckLoadedLearner(LearnerCore& learner) {
  const PolicyWeights weights = learner.CurrentWeights();
  for (const at::Tensor& parameter : weights.parameters) {
    if (!at::isfinite(parameter).all().item<bool>()) {
      FuzzFail("a loaded learner would publish non-finite weights",
               absl::InternalError(""));
    }
  }
  const LearnerConfig& config = learner.config();
  SegmentQueue queue(config.rollouts_per_batch);
  for (int64_t slot = 0; slot < config.rollouts_per_batch; ++slot) {
    (void)queue.Send(FuzzSegment(config.spec, config.horizon, slot,
                                 learner.policy_version(), slot));
  }
  queue.Close();
  absl::StatusOr<UpdateStats> stats = learner.RunUpdate(queue);
  if (!stats.ok()) FuzzFail("a loaded learner cannot update", stats.status());
}

std::string FuzzTempPath(const std::string& name) {
  const char* dir = std::getenv("TMPDIR");
  return absl::StrCat(dir != nullptr && *dir != '\0' ? dir : "/tmp",
                      "/vantage_", ::getpid(), "_", name);
}

void FuzzFail(const char* what, const absl::Status& status) {
  std::fprintf(stderr, "fuzz invariant broken: %s: %s\n", what,
               status.ToString().c_str());
  std::abort();
}

}  // namespace vantage
