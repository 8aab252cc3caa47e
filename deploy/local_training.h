#ifndef VANTAGE_DEPLOY_LOCAL_TRAINING_H_
#define VANTAGE_DEPLOY_LOCAL_TRAINING_H_

#include <cstdint>
#include <functional>
#include <string>

#include "absl/status/status.h"
#include "actor/actor_core.h"
#include "learner/learner_core.h"

namespace vantage {

struct LocalTrainingConfig {
  std::string env = "InvertedPendulum";
  int num_envs = 1;
  int64_t total_env_steps = 300000;
  uint64_t seed = 0;
  LearnerConfig learner;  // spec, rollouts_per_batch and total steps filled in
};

// `--mode=local`: one actor core and one learner core in this process,
// connected by an in-process queue, strictly on-policy: the actor collects
// one horizon per environment with the latest weights, the learner updates
// and publishes the next version. `on_update` sees every update with the
// mean return of the last 100 episodes (NaN before the first one ends).
absl::Status RunLocalTraining(
    const LocalTrainingConfig& config,
    const std::function<void(const UpdateStats&, double)>& on_update);

}  // namespace vantage

#endif  // VANTAGE_DEPLOY_LOCAL_TRAINING_H_
