#include "deploy/local_training.h"

#include <cmath>
#include <limits>
#include <numeric>

namespace vantage {

absl::Status RunLocalTraining(
    const LocalTrainingConfig& config,
    const std::function<void(const UpdateStats&, double)>& on_update) {
  ActorConfig actor_config;
  actor_config.env = config.env;
  actor_config.num_envs = config.num_envs;
  actor_config.segment_length = config.learner.horizon;
  actor_config.seed = config.seed;
  actor_config.network = config.learner.network;
  actor_config.observation_clip = config.learner.observation_clip;
  absl::StatusOr<std::unique_ptr<ActorCore>> actor =
      ActorCore::Create(actor_config);
  if (!actor.ok()) return actor.status();

  LearnerConfig learner_config = config.learner;
  learner_config.spec = (*actor)->spec();
  learner_config.rollouts_per_batch = config.num_envs;
  learner_config.max_segment_steps = config.learner.horizon;
  learner_config.total_env_steps = config.total_env_steps;
  learner_config.seed = config.seed;
  absl::StatusOr<std::unique_ptr<LearnerCore>> learner =
      LearnerCore::Create(learner_config);
  if (!learner.ok()) return learner.status();

  SegmentQueue queue(static_cast<size_t>(config.num_envs));
  int64_t steps = 0;
  while (steps < config.total_env_steps) {
    if (absl::Status status =
            (*actor)->SetWeights((*learner)->CurrentWeights());
        !status.ok()) {
      return status;
    }
    if (absl::Status status = (*actor)->CollectSegments(queue); !status.ok()) {
      return status;
    }
    absl::StatusOr<UpdateStats> stats = (*learner)->RunUpdate(queue);
    if (!stats.ok()) return stats.status();
    steps = stats->env_steps;
    const auto& returns = (*learner)->recent_returns();
    const double mean_return =
        returns.empty() ? std::numeric_limits<double>::quiet_NaN()
                        : std::accumulate(returns.begin(), returns.end(), 0.0) /
                              returns.size();
    on_update(*stats, mean_return);
  }
  return absl::OkStatus();
}

}  // namespace vantage
