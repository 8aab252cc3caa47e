#include "deploy/run/run_plan.h"

#include "absl/strings/str_cat.h"
#include "actor/run_settings.h"
#include "common/advantage/advantage_config.h"
#include "deploy/run/run_config.h"
#include "learner/algorithms/algorithm_config.h"
#include "learner/exploration/ex2_config.h"

namespace vantage {
namespace {

absl::StatusOr<AdvantageConfig> AdvantageConfigOf(const pb::RunConfig& c) {
  const pb::AdvantageSettings& a = c.advantage();
  AdvantageConfig advantage;
  absl::StatusOr<Statistic> statistic = ParseStatistic(a.estimator());
  if (!statistic.ok()) return statistic.status();
  advantage.statistic = *statistic;
  advantage.rho = a.rho();
  advantage.gamma = a.gamma();
  advantage.lambda = a.gae_lambda();
  advantage.ensemble.assign(a.ensemble().begin(), a.ensemble().end());
  return advantage;
}

// Everything of the learner but the env's spec.
absl::StatusOr<LearnerConfig> LearnerConfigOf(const pb::RunConfig& c,
                                              const ActorConfig& actor) {
  const pb::TrainingSettings& t = c.training();
  LearnerConfig learner;
  learner.horizon = t.horizon();
  learner.rollouts_per_batch = t.envs();
  learner.max_segment_steps = t.segment_length();
  learner.max_policy_lag = c.distributed().max_policy_lag();
  learner.total_env_steps = t.steps();
  learner.seed = t.seed();
  learner.scale_rewards = t.scale_rewards();
  // The learner trains the network its actors run, and both clip
  // observations alike.
  learner.network = actor.network;
  learner.observation_clip = actor.observation_clip;
  absl::StatusOr<AdvantageConfig> advantage = AdvantageConfigOf(c);
  if (!advantage.ok()) return advantage.status();
  learner.advantage = *std::move(advantage);
  learner.algorithm = AlgorithmConfigOf(c);
  learner.exploration = ExplorationConfigOf(c);
  return learner;
}

}  // namespace

absl::StatusOr<RunPlan> PlanRun(const pb::RunConfig& resolved) {
  RunPlan plan;
  absl::StatusOr<ActorConfig> actor = ActorConfigOf(resolved);
  if (!actor.ok()) return actor.status();
  plan.actor = *std::move(actor);
  absl::StatusOr<LearnerConfig> learner = LearnerConfigOf(resolved, plan.actor);
  if (!learner.ok()) return learner.status();
  plan.learner = *std::move(learner);
  plan.recording = RecordingConfigOf(resolved.recording());
  plan.recording.config_json = RunConfigToJson(resolved);
  return plan;
}

}  // namespace vantage
