#ifndef VANTAGE_TESTS_FAKES_UPDATER_FIXTURES_H_
#define VANTAGE_TESTS_FAKES_UPDATER_FIXTURES_H_

// What the first-order updaters' tests (PPO, A2C) share: a pair of
// networks from a seed, a batch acted by their policy, updater state
// through checkpoint bytes, and parameters compared to a tolerance.

#include <ATen/ATen.h>
#include <gtest/gtest.h>
#include <torch/serialize/input-archive.h>
#include <torch/serialize/output-archive.h>

#include <algorithm>
#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "common/nn/networks.h"
#include "learner/algorithms/chunk_minibatches.h"
#include "learner/algorithms/policy_updater.h"

namespace vantage {

struct Networks {
  PolicyNetwork policy{nullptr};
  ValueNetwork value{nullptr};
  std::vector<at::Tensor> parameters() {
    return NetworkParameters(*policy, *value);
  }
};

// The default networks of `spec`, their weights drawn after seeding
// LibTorch's generator with `seed`.
inline Networks MakeNetworks(const EnvSpec& spec, uint64_t seed,
                             const NetworkConfig& config = NetworkConfig()) {
  at::manual_seed(seed);
  Networks n;
  n.policy = PolicyNetwork(spec, config);
  n.value = MakeValueNetwork(spec, config, *n.policy);
  return n;
}

// Actions drawn from the policy's `output` for the batch's rows, behaviour
// log-probabilities of a slightly different policy, random advantages and
// returns.
inline void ActOn(Networks& n, const at::Tensor& output, UpdateBatch& batch) {
  const int64_t samples = output.size(0);
  batch.actions = n.policy->Act(output, false, at::Generator());
  batch.behaviour_log_probs =
      n.policy->LogProb(output, batch.actions) + 0.2 * at::randn({samples});
  batch.advantages = at::randn({samples});
  batch.returns = at::randn({samples});
}

// `horizon` x `streams` steps acted by `n`'s policy (actions drawn from
// it) whose behaviour log-probabilities are those of a slightly different
// policy, so that ratios start near 1 and some leave a clipping range.
inline UpdateBatch ActedBatch(const EnvSpec& spec, Networks& n, int64_t horizon,
                              int64_t streams) {
  at::NoGradGuard no_grad;
  const int64_t samples = horizon * streams;
  UpdateBatch batch;
  batch.horizon = horizon;
  batch.streams = streams;
  batch.observations = at::randn({samples, spec.observation_size});
  ActOn(n, n.policy->forward(batch.observations), batch);
  return batch;
}

// The same for a recurrent policy (`n` has a core): `streams` rollouts of
// `horizon` steps in chunks of `seq_len`, episodes starting at random
// steps, random chunk start states.
inline UpdateBatch RecurrentActedBatch(const EnvSpec& spec, Networks& n,
                                       int64_t horizon, int64_t streams,
                                       int64_t seq_len) {
  at::NoGradGuard no_grad;
  const int64_t samples = horizon * streams;
  UpdateBatch batch;
  batch.horizon = horizon;
  batch.streams = streams;
  batch.seq_len = seq_len;
  batch.observations = at::randn({samples, spec.observation_size});
  batch.starts = at::rand({samples}) < 0.05;
  batch.chunk_states = at::randn({horizon / seq_len * streams,
                                  n.policy->trunk()->state_size()}) *
                       0.3;
  const ChunkMinibatch all = ChunksOfSteps(batch, 0, horizon);
  const at::Tensor chunked = RunChunks(*n.policy, *n.value, batch, all).policy;
  const at::Tensor output =
      at::empty_like(chunked).index_copy_(0, all.rows, chunked);
  ActOn(n, output, batch);
  return batch;
}

inline std::string Saved(const PolicyUpdater& updater) {
  torch::serialize::OutputArchive archive;
  updater.Save(archive);
  std::ostringstream bytes;
  archive.save_to(bytes);
  return bytes.str();
}

inline absl::Status LoadInto(PolicyUpdater& updater, const std::string& bytes) {
  torch::serialize::InputArchive archive;
  std::istringstream in(bytes);
  archive.load_from(in);
  return updater.Load(archive);
}

// Each parameter within `tolerance` of its tensor's largest magnitude.
inline void ExpectSameParameters(const std::vector<at::Tensor>& got,
                                 const std::vector<at::Tensor>& want,
                                 double tolerance) {
  ASSERT_EQ(got.size(), want.size());
  for (size_t i = 0; i < got.size(); ++i) {
    const double scale = std::max(1e-12, want[i].abs().max().item<double>());
    EXPECT_LE((got[i] - want[i]).abs().max().item<double>() / scale, tolerance)
        << "parameter " << i;
  }
}

}  // namespace vantage

#endif  // VANTAGE_TESTS_FAKES_UPDATER_FIXTURES_H_
