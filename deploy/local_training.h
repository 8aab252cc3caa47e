#ifndef VANTAGE_DEPLOY_LOCAL_TRAINING_H_
#define VANTAGE_DEPLOY_LOCAL_TRAINING_H_

#include <atomic>
#include <cstdint>
#include <functional>
#include <string>

#include "absl/status/status.h"
#include "actor/actor_core.h"
#include "actor/envs/env_registry.h"
#include "deploy/run_directory.h"
#include "learner/learner_core.h"

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

  // Optional run directory (see deploy/run_directory.h): config.json with
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

// `--mode=local`: one actor core and one learner core in this process,
// connected by an in-process queue, strictly on-policy: the actor collects
// one horizon per environment with the latest weights, the learner updates
// and publishes the next version. `on_update` sees every update (after its
// progress row and checkpoint are written) and returns false to stop the
// run there, as an interruption would (a later resume continues it). Once
// `stop` (if given) is set, the run stops after the update in progress with
// a checkpoint of it, as a signalled learner does, and returns OK.
absl::Status RunLocalTraining(
    const LocalTrainingConfig& config,
    const std::function<bool(const ProgressRow&)>& on_update,
    const std::atomic<bool>* stop = nullptr);

}  // namespace vantage

#endif  // VANTAGE_DEPLOY_LOCAL_TRAINING_H_
