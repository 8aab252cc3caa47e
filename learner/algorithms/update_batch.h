#ifndef VANTAGE_LEARNER_ALGORITHMS_UPDATE_BATCH_H_
#define VANTAGE_LEARNER_ALGORITHMS_UPDATE_BATCH_H_

// What every learning algorithm trains on: the batch as the learner's batch
// stage hands it over.

#include <ATen/core/Tensor.h>

#include <cstdint>

namespace vantage {

// N env streams x T steps flattened time-major: row t * N + n.
struct UpdateBatch {
  int64_t horizon = 0;             // T
  int64_t streams = 0;             // N
  at::Tensor observations;         // [T*N, obs], normalised
  at::Tensor actions;              // [T*N, act]
  at::Tensor behaviour_log_probs;  // [T*N] of the policy that acted
  at::Tensor advantages;           // [T*N] rho-mixed: the policy's
  at::Tensor returns;              // [T*N] V + GAE: the critic's
  // Masked discrete actions: [T*N, actions] bool, the legal actions the
  // actor sampled from, which every policy output is scored under
  // (MaskLogits); undefined otherwise.
  at::Tensor action_masks;
  // Some steps were acted by an older version than the one updating (an
  // asynchronous run's lag).
  bool lagged = false;
  // Recurrent policies train on chunks of seq_len steps of one stream
  // (seq_len divides T; 0: a feed-forward policy): `starts` [T*N] bool
  // marks where episodes start (the core's state is zeroed before the
  // step), `chunk_states` [T/seq_len * N, state] is the state before each
  // chunk (chunk c of stream n at row c * N + n).
  int64_t seq_len = 0;
  at::Tensor starts;
  at::Tensor chunk_states;
};

}  // namespace vantage

#endif  // VANTAGE_LEARNER_ALGORITHMS_UPDATE_BATCH_H_
