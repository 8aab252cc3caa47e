#ifndef VANTAGE_LEARNER_BATCH_TRAINING_BATCH_H_
#define VANTAGE_LEARNER_BATCH_TRAINING_BATCH_H_

#include <ATen/core/Tensor.h>

#include <vector>

#include "absl/functional/function_ref.h"
#include "absl/status/statusor.h"
#include "common/advantage/advantage.h"
#include "learner/algorithms/update_batch.h"
#include "learner/ingest/rollout_stitcher.h"

namespace vantage {

// N rollouts of T steps side by side, ready for the advantage estimators
// (columns = env streams) and the update.
struct TrainingBatch {
  AdvantageInputs advantage_inputs;  // [T, N]; values from the current critic
  at::Tensor observations;           // [T, N, obs], as the actors saw them
  at::Tensor actions;                // [T, N, act]
  at::Tensor behaviour_log_probs;    // [T, N]
  at::Tensor policy_versions;        // [T, N] int64
  // Masked discrete actions: [T, N, actions] bool; undefined otherwise.
  at::Tensor action_masks;
  // Recurrent policies: where episodes start ([T, N] bool: the core's state
  // is zeroed before the step) and the core's state before each chunk of
  // seq_len steps ([T / seq_len * N, state], chunk c of stream n at row
  // c * N + n), from the learner's own pass over the rollouts.
  at::Tensor starts;
  at::Tensor chunk_states;
  int64_t seq_len = 0;
  // [T, N] int64: the step of its episode each observation is, where every
  // rollout says (Rollout::episode_steps); undefined otherwise.
  at::Tensor episode_steps;
};

// The critic's values of every observation the estimators need, in this
// order: each rollout's T + 1 observations, rollout after rollout, then
// each rollout's final observations (of its truncated steps), in order.
using CriticValuesOf =
    absl::FunctionRef<at::Tensor(const std::vector<Rollout>&)>;

// Evaluates the learner's critic once over every observation the
// estimators need: V(s_t), V(s_T) after each rollout's last step, and V of
// the final observation at each truncated step (the others are 0 and never
// read). All rollouts must have the same length.
absl::StatusOr<TrainingBatch> AssembleBatch(
    const std::vector<Rollout>& rollouts, CriticValuesOf values_of);

// A return that ends at each time limit, as at a terminal step (rllab's
// and the baselines' samplers): every truncated step bootstraps with 0
// instead of the critic's value of the state after it.
void EndReturnsAtTimeLimits(AdvantageInputs& inputs);

// Where episodes start in a batch's [T, N] step flags: after every step
// that ended one (never at step 0, whose state the rollout carries).
at::Tensor EpisodeStarts(const at::Tensor& terminated,
                         const at::Tensor& truncated);

// What the algorithm trains on, flattened time-major: the policy gets the
// rho-mixed advantages, the critic ALWAYS the normal targets V + GAE
// (whatever rho is). `normalize` maps raw observations to the network's
// inputs.
UpdateBatch MakeUpdateBatch(
    const TrainingBatch& batch, const Advantages& advantages,
    absl::FunctionRef<at::Tensor(const at::Tensor&)> normalize);

}  // namespace vantage

#endif  // VANTAGE_LEARNER_BATCH_TRAINING_BATCH_H_
