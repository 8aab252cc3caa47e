#ifndef VANTAGE_DEPLOY_RUN_LOCAL_TRAINING_CONFIG_H_
#define VANTAGE_DEPLOY_RUN_LOCAL_TRAINING_CONFIG_H_

// A run of the learning code in this process (deploy/run/local_training.h) and
// of each learner process, as the run configuration resolves it; without
// the actor and learner cores, so that what only reads or checks settings
// compiles without LibTorch.

#include <cstdint>
#include <string>

#include "actor/envs/env_registry.h"
#include "common/env/environment.h"
#include "learner/learner_config.h"

namespace vantage {

struct LocalTrainingConfig {
  std::string env = "InvertedPendulum";
  EnvOptions env_options;
  int num_envs = 1;
  int64_t total_env_steps = 150000;
  uint64_t seed = 0;
  LearnerConfig learner;  // spec, rollouts_per_batch and total steps filled in
  // Steps per segment (must divide learner.horizon; 0: the horizon). The
  // same segments as a distributed run's make the two runs' progress equal.
  int64_t segment_length = 0;

  // Optional run directory (see deploy/run/run_directory.h): config.json with
  // `config_json`, progress.csv, and a checkpoint every `checkpoint_every`
  // updates and at the end, keeping the newest `keep_checkpoints`.
  std::string run_dir;
  std::string config_json;
  int checkpoint_every = 10;
  int keep_checkpoints = 3;
  // Continue the run in run_dir from its newest readable checkpoint (an
  // unreadable one is reported and the one before it used); the continued
  // run's progress equals an uninterrupted run's.
  bool resume = false;
  // False for the replicas of a data-parallel run other than rank 0: they
  // read run_dir's checkpoints to resume but write nothing there.
  bool record = true;
};

// The learner's config for `config` and the environment's spec.
LearnerConfig MakeLearnerConfig(const LocalTrainingConfig& config,
                                const EnvSpec& spec);

}  // namespace vantage

#endif  // VANTAGE_DEPLOY_RUN_LOCAL_TRAINING_CONFIG_H_
