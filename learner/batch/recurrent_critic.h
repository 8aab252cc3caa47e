#ifndef VANTAGE_LEARNER_BATCH_RECURRENT_CRITIC_H_
#define VANTAGE_LEARNER_BATCH_RECURRENT_CRITIC_H_

// The critic of a recurrent policy over a batch: its trunk runs along each
// rollout from the state the rollout's first segment carries, zeroing it
// where episodes start, and the states it passes through are what each
// chunk of the update starts from.

#include <ATen/core/Tensor.h>

#include <cstdint>
#include <vector>

#include "absl/functional/function_ref.h"
#include "learner/ingest/rollout_stitcher.h"

namespace vantage {

class ValueNetworkImpl;

struct RecurrentCriticPass {
  // AssembleBatch's order (training_batch.h: CriticValuesOf).
  at::Tensor values;
  // The rollouts' start states [N, state] and the state after each of
  // their T steps [T, N, state].
  at::Tensor start_states;
  at::Tensor after;
};

// `normalize` maps raw observations to the networks' inputs. The value of
// a truncated step's final observation is that of one more step from the
// state after it (the episode goes on there, as the env saw it).
RecurrentCriticPass RunRecurrentCritic(
    ValueNetworkImpl& value, const std::vector<Rollout>& rollouts,
    absl::FunctionRef<at::Tensor(const at::Tensor&)> normalize);

// The state before each chunk of `seq_len` steps [T / seq_len * N, state]
// (chunk c of stream n at row c * N + n); seq_len divides T.
at::Tensor ChunkStartStates(const RecurrentCriticPass& pass, int64_t seq_len);

}  // namespace vantage

#endif  // VANTAGE_LEARNER_BATCH_RECURRENT_CRITIC_H_
