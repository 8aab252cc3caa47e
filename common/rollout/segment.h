#ifndef VANTAGE_COMMON_ROLLOUT_SEGMENT_H_
#define VANTAGE_COMMON_ROLLOUT_SEGMENT_H_

// What actors send and the learner stitches: a stretch of one environment
// stream acted by one policy version.

#include <ATen/core/Tensor.h>

#include <cstdint>
#include <vector>

#include "absl/status/status.h"
#include "common/env/environment.h"
#include "common/rollout/value_limits.h"

namespace vantage {

struct Segment {
  int64_t actor_id = 0;
  int64_t env_slot = 0;
  // Consecutive per (actor, slot); a gap (a restarted actor) starts a new
  // stream that is never stitched onto the old one.
  int64_t sequence = 0;
  int64_t policy_version = 0;

  // T steps; all float32 unless noted. Observations are uint8 instead when
  // the spec says they are bytes (EnvSpec::observation_high > 0).
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
  // A recurrent policy's state before step 0 [state size] (zero if an
  // episode starts there); undefined for a feed-forward policy.
  at::Tensor core_state;
  // [T, actions] bool: the legal actions at each step, for masked discrete
  // actions (EnvSpec::action_masks); undefined otherwise.
  at::Tensor action_masks;

  // Episodes that ended inside this segment.
  std::vector<double> episode_returns;
  std::vector<int64_t> episode_lengths;
  // The step of its episode that step 0 is (0: an episode starts there);
  // each later step counts on from it, and from 0 after an episode's end.
  int64_t first_episode_step = 0;

  // 0 for a rewards tensor that is missing or has no time axis (which
  // ValidateSegment refuses).
  int64_t steps() const {
    return rewards.defined() && rewards.dim() >= 1 ? rewards.size(0) : 0;
  }
};

// Everything a learner must check before a segment touches training data:
// shapes against the spec, dtypes, finite numbers within `limits` (byte
// observations within the spec's observation_high), T in
// [1, max_steps], one final observation per truncated step, no step both
// terminated and truncated, and one finite episode return and length per
// episode end (terminated or truncated step), each length >= 1, no longer
// than the steps since the previous end in the segment (the first may have
// begun in an earlier segment) nor than spec.max_episode_steps, each return
// within max_abs_reward * length, and a core_state of exactly
// `core_state_size` finite floats within max_abs_observation (none when 0;
// with one, exactly max_steps steps), and for masked actions a mask
// [T, actions] whose every row has a legal action, the one taken, and a
// first_episode_step >= 0, below spec.max_episode_steps when it has one.
// The message names the field.
absl::Status ValidateSegment(const Segment& segment, const EnvSpec& spec,
                             int64_t max_steps, const ValueLimits& limits = {},
                             int64_t core_state_size = 0);

}  // namespace vantage

#endif  // VANTAGE_COMMON_ROLLOUT_SEGMENT_H_
