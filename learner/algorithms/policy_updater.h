#ifndef VANTAGE_LEARNER_ALGORITHMS_POLICY_UPDATER_H_
#define VANTAGE_LEARNER_ALGORITHMS_POLICY_UPDATER_H_

// What every learning algorithm (PPO, A2C, TRPO) does with a batch: the
// learner core hands over the estimates, the algorithm changes the networks.

#include <ATen/core/Tensor.h>

#include <cstdint>
#include <random>

#include "absl/status/status.h"
#include "learner/algorithms/algorithm_stats.h"

namespace torch::serialize {
class InputArchive;
class OutputArchive;
}  // namespace torch::serialize

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
  // Some steps were acted by an older version than the one updating (an
  // asynchronous run's lag).
  bool lagged = false;
};

class PolicyUpdater {
 public:
  virtual ~PolicyUpdater() = default;

  // `progress` in [0, 1] is the share of the run's env steps done (learning
  // rates decay linearly to 0 at 1). `rng` draws the minibatch order.
  virtual AlgorithmStats Update(const UpdateBatch& batch, double progress,
                                std::mt19937_64& rng) = 0;

  // The optimisers' state, for checkpoints.
  virtual void Save(torch::serialize::OutputArchive& archive) const = 0;
  virtual absl::Status Load(torch::serialize::InputArchive& archive) = 0;
};

}  // namespace vantage

#endif  // VANTAGE_LEARNER_ALGORITHMS_POLICY_UPDATER_H_
