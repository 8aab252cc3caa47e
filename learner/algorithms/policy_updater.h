#ifndef VANTAGE_LEARNER_ALGORITHMS_POLICY_UPDATER_H_
#define VANTAGE_LEARNER_ALGORITHMS_POLICY_UPDATER_H_

// What every learning algorithm (PPO, A2C, TRPO) does with a batch: the
// learner core hands over the estimates, the algorithm changes the networks.
// PPO and A2C share more (first_order_updater.h).

#include <ATen/core/Tensor.h>

#include <cstdint>
#include <memory>
#include <random>
#include <utility>

#include "absl/status/status.h"
#include "common/nn/networks.h"
#include "learner/algorithms/algorithm_stats.h"
#include "learner/algorithms/update_batch.h"
#include "learner/parallel/replica_group.h"

namespace torch::serialize {
class InputArchive;
class OutputArchive;
}  // namespace torch::serialize

namespace vantage {

// An algorithm's update, and what every algorithm works on: the two
// networks it changes and the data-parallel replicas it averages over.
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

 protected:
  PolicyUpdater(PolicyNetwork policy, ValueNetwork value,
                std::shared_ptr<ReplicaGroup> replicas)
      : policy_(std::move(policy)),
        value_(std::move(value)),
        replicas_(std::move(replicas)) {}

  PolicyNetwork policy_;
  ValueNetwork value_;
  std::shared_ptr<ReplicaGroup> replicas_;
};

}  // namespace vantage

#endif  // VANTAGE_LEARNER_ALGORITHMS_POLICY_UPDATER_H_
