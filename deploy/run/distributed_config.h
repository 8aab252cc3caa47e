#ifndef VANTAGE_DEPLOY_RUN_DISTRIBUTED_CONFIG_H_
#define VANTAGE_DEPLOY_RUN_DISTRIBUTED_CONFIG_H_

// How a distributed run is laid out on processes: what the launcher starts
// and how the learner takes its batches. Without LibTorch.

#include <cstdint>

#include "absl/status/status.h"

namespace vantage {
namespace pb {
class DistributedSettings;
class TrainingSettings;
}  // namespace pb

struct DistributedConfig {
  int actors = 2;          // actor processes
  int envs_per_actor = 1;  // environments (rollout streams) of each
  // Each batch only from the newest policy version; else asynchronous
  // within max_policy_lag versions.
  bool sync = true;
  int64_t max_policy_lag = 0;
  int learners = 1;  // data-parallel learner processes
  // LibTorch intra-op threads of each learner (0: the cores over the
  // learners); one beat two on the 2-core machines measured (small GEMMs).
  int learner_threads = 1;
  // An actor that owes segments and sends none for this long is replaced
  // (see pb::DistributedSettings).
  double actor_stall_timeout_s = 60;

  // Each setting within its range (the message names the flag).
  absl::Status Validate() const;
};

// The run config's distributed section with every absent setting given
// its default, checked, given the training section (whose --envs, when
// given alone, is split over the actors); the rules that tie it to the
// training section (the streams are the learner's batch) included. Its
// table is in distributed_config.cc.
absl::Status ResolveDistributedSettings(pb::TrainingSettings& training,
                                        pb::DistributedSettings& settings);

}  // namespace vantage

#endif  // VANTAGE_DEPLOY_RUN_DISTRIBUTED_CONFIG_H_
