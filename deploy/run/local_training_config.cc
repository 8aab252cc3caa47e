#include "deploy/run/local_training_config.h"

namespace vantage {

LearnerConfig MakeLearnerConfig(const LocalTrainingConfig& config,
                                const EnvSpec& spec) {
  LearnerConfig learner = config.learner;
  learner.spec = spec;
  learner.rollouts_per_batch = config.num_envs;
  learner.max_segment_steps = config.learner.horizon;
  learner.total_env_steps = config.total_env_steps;
  learner.seed = config.seed;
  return learner;
}

}  // namespace vantage
