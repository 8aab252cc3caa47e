#ifndef VANTAGE_COMMON_ROLLOUT_SEGMENT_H_
#define VANTAGE_COMMON_ROLLOUT_SEGMENT_H_

// What actors send and the learner stitches: a stretch of one environment
// stream acted by one policy version.

#include <ATen/core/Tensor.h>

#include <cstdint>
#include <vector>

#include "absl/status/status.h"
#include "common/env/environment.h"

namespace vantage {

struct Segment {
  int64_t actor_id = 0;
  int64_t env_slot = 0;
  // Consecutive per (actor, slot); a gap (a restarted actor) starts a new
  // stream that is never stitched onto the old one.
  int64_t sequence = 0;
  int64_t policy_version = 0;

  // T steps; all float32 unless noted.
  at::Tensor observations;  // [T + 1, obs]: s_0 .. s_T, s_T after the last step
  at::Tensor actions;       // [T, act] (discrete: [T, 1] indices)
  at::Tensor rewards;       // [T]
  at::Tensor terminated;    // [T] bool
  at::Tensor truncated;     // [T] bool
  // [K, obs]: the final observations of the K truncated steps, in order
  // (where the env reset, observations holds the next episode's start).
  at::Tensor final_observations;
  // [T]: log pi_behaviour(a_t | s_t) of the policy version that acted.
  at::Tensor behaviour_log_probs;

  // Episodes that ended inside this segment.
  std::vector<double> episode_returns;
  std::vector<int64_t> episode_lengths;

  int64_t steps() const { return rewards.defined() ? rewards.size(0) : 0; }
};

// Everything a learner must check before a segment touches training data:
// shapes against the spec, dtypes, finite numbers, T in [1, max_steps],
// one final observation per truncated step, no step both terminated and
// truncated. The message names the field.
absl::Status ValidateSegment(const Segment& segment, const EnvSpec& spec,
                             int64_t max_steps);

}  // namespace vantage

#endif  // VANTAGE_COMMON_ROLLOUT_SEGMENT_H_
