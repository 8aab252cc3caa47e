#include "learner/batch/recurrent_critic.h"

#include <ATen/ATen.h>
#include <ATen/core/grad_mode.h>

#include "common/nn/networks.h"

namespace vantage {
namespace {

at::Tensor StackField(const std::vector<Rollout>& rollouts,
                      at::Tensor Rollout::*field) {
  std::vector<at::Tensor> columns;
  for (const Rollout& rollout : rollouts) columns.push_back(rollout.*field);
  return at::stack(columns, 1);
}

}  // namespace

RecurrentCriticPass RunRecurrentCritic(
    ValueNetworkImpl& value, const std::vector<Rollout>& rollouts,
    absl::FunctionRef<at::Tensor(const at::Tensor&)> normalize) {
  at::NoGradGuard no_grad;
  RecurrentTrunk holder = value.trunk();  // shares the module
  RecurrentTrunkImpl& trunk = *holder;
  const int64_t n = static_cast<int64_t>(rollouts.size());
  const at::Tensor observations =
      StackField(rollouts, &Rollout::observations);  // [T + 1, N, obs]
  const int64_t steps = observations.size(0) - 1;
  // s_T after the last step is unrolled too: a step past the rollout,
  // starting an episode where the last step ended one.
  const at::Tensor ended =
      at::logical_or(StackField(rollouts, &Rollout::terminated),
                     StackField(rollouts, &Rollout::truncated));
  const at::Tensor starts =
      at::cat({at::zeros({1, n}, at::kBool), ended});  // [T + 1, N]
  RecurrentCriticPass pass;
  std::vector<at::Tensor> start_states;
  for (const Rollout& rollout : rollouts) {
    start_states.push_back(rollout.core_state);
  }
  pass.start_states = at::stack(start_states);
  at::Tensor after;
  const at::Tensor features = trunk.UnrollWithoutGradients(
      normalize(observations.reshape({(steps + 1) * n, -1})), starts,
      pass.start_states, &after);
  pass.after = after.slice(0, 0, steps);
  // Rollout-major, as AssembleBatch reads them.
  const at::Tensor stream_values =
      value.Head(features).reshape({steps + 1, n}).t().reshape({-1});
  // The truncated steps' final observations, from the state after them.
  std::vector<at::Tensor> final_states, finals;
  for (int64_t column = 0; column < n; ++column) {
    const at::Tensor rows =
        at::nonzero(rollouts[column].truncated).reshape({-1});
    final_states.push_back(pass.after.select(1, column).index_select(0, rows));
    finals.push_back(rollouts[column].final_observations);
  }
  const at::Tensor final_observations = at::cat(finals);
  if (final_observations.size(0) == 0) {
    pass.values = stream_values;
    return pass;
  }
  const at::Tensor next = trunk.Step(
      trunk.Encode(normalize(final_observations)), at::cat(final_states));
  pass.values = at::cat({stream_values, value.Head(trunk.Hidden(next))});
  return pass;
}

at::Tensor ChunkStartStates(const RecurrentCriticPass& pass, int64_t seq_len) {
  const int64_t steps = pass.after.size(0);
  std::vector<at::Tensor> states = {pass.start_states};
  for (int64_t begin = seq_len; begin < steps; begin += seq_len) {
    states.push_back(pass.after[begin - 1]);
  }
  return at::cat(states);
}

}  // namespace vantage
