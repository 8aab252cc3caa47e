#ifndef VANTAGE_LEARNER_LEARNER_CONFIG_H_
#define VANTAGE_LEARNER_LEARNER_CONFIG_H_

// What a learner is configured with, without LibTorch: the run
// configuration builds it, the learner core (learner_core.h) runs it.

#include <cstdint>
#include <limits>

#include "absl/status/status.h"
#include "common/advantage/advantage_config.h"
#include "common/env/environment.h"
#include "common/nn/network_config.h"
#include "common/rollout/value_limits.h"
#include "learner/algorithms/algorithm_config.h"
#include "learner/exploration/ex2_config.h"

namespace vantage {

struct LearnerConfig {
  EnvSpec spec;
  int64_t horizon = 2048;  // steps per rollout and env stream
  // Env streams per update of this learner (of each replica, in a
  // data-parallel run: the global batch is world_size times as large).
  int64_t rollouts_per_batch = 1;
  int64_t max_segment_steps = 4096;
  // Steps acted by a policy older than version - max_policy_lag are
  // dropped and counted (0: strictly on-policy, the sync mode); -1: any.
  int64_t max_policy_lag = 0;
  int64_t total_env_steps = 1000000;  // the learning rate decays to 0 there
  uint64_t seed = 0;
  double observation_clip = 10.0;
  // Divide rewards by the running std of discounted returns (then clip).
  bool scale_rewards = false;
  // Observations normalised by their running statistics (else the
  // normaliser keeps its initial mean 0 and variance 1 and the networks
  // see the environment's values, observation_clip then infinite).
  bool normalize_observations = true;
  // A step cut off by the time limit bootstraps with the critic's value of
  // the state after it (else its return ends there, as at a terminal step).
  bool bootstrap_time_limits = true;
  double reward_clip = 10.0;
  // An update with a larger global gradient norm (before clipping) in any
  // of its gradient steps is rolled back like one that produced non-finite
  // numbers; infinite: only non-finite numbers roll back.
  double rollback_gradient_norm = std::numeric_limits<double>::infinity();
  // Steps the stitcher may hold in partial rollouts over all streams; past
  // it, the least recently fed streams are dropped (counted in
  // evicted_steps). 0: 8 batches (horizon * rollouts_per_batch * 8).
  int64_t max_buffered_steps = 0;
  // What a segment's values must stay within (see ValidateSegment).
  ValueLimits value_limits;
  AdvantageConfig advantage;
  AlgorithmConfig algorithm;
  NetworkConfig network;
  // A bonus added to the rewards before advantages (none by default).
  ExplorationConfig exploration;

  // Whether the critic is the linear feature baseline (TRPO's
  // --trpo_linear_baseline) rather than the value network.
  bool linear_critic() const;
  // Whether there is no critic at all (TRPO's --trpo_zero_baseline): every
  // state is valued 0.
  bool zero_critic() const;
  // Everything, the spec and the network's fit to it included.
  absl::Status Validate() const;
  // Every rule that holds without the env's spec (what a run config
  // decides before any environment exists).
  absl::Status ValidateSettings() const;
};

}  // namespace vantage

#endif  // VANTAGE_LEARNER_LEARNER_CONFIG_H_
