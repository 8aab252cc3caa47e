#ifndef VANTAGE_LEARNER_ALGORITHMS_A2C_A2C_UPDATER_H_
#define VANTAGE_LEARNER_ALGORITHMS_A2C_A2C_UPDATER_H_

#include <memory>
#include <optional>
#include <vector>

#include "absl/status/status.h"
#include "common/nn/networks.h"
#include "learner/algorithms/a2c/a2c_config.h"
#include "learner/algorithms/a2c/flat_rmsprop.h"
#include "learner/algorithms/flat_actor_critic.h"
#include "learner/algorithms/policy_updater.h"
#include "learner/parallel/replica_group.h"

namespace torch::optim {
class Optimizer;
}  // namespace torch::optim

namespace vantage {

// A2C: per minibatch one RMSProp step (a2c.rmsprop's arithmetic) on
// -mean(log pi(a|s) A) + value_coef * value loss - entropy_coef * entropy.
// MLP networks train through FlatActorCritic and FlatRmsprop (the same
// steps without autograd); convolutional ones, or every network when
// `autograd_only`, through LibTorch's autograd.
class A2cUpdater : public PolicyUpdater {
 public:
  static constexpr bool kOneOptimizer = true;

  // `replicas`: the data-parallel learners whose gradients are averaged.
  A2cUpdater(PolicyNetwork policy, ValueNetwork value, const A2cConfig& config,
             std::shared_ptr<ReplicaGroup> replicas = SoloReplicaGroup(),
             bool autograd_only = false);
  ~A2cUpdater() override;

  // The batch's horizon must be a multiple of steps_per_minibatch; the
  // minibatches are its consecutive time slices, oldest first.
  AlgorithmStats Update(const UpdateBatch& batch, double progress,
                        std::mt19937_64& rng) override;
  void Save(torch::serialize::OutputArchive& archive) const override;
  absl::Status Load(torch::serialize::InputArchive& archive) override;

  // Whether updates bypass autograd.
  bool flat() const { return flat_.has_value(); }

 private:
  // Each over the batch's consecutive minibatches of `rows` rows.
  AlgorithmStats AutogradUpdate(const UpdateBatch& batch, int64_t rows);
  AlgorithmStats FlatUpdate(const UpdateBatch& batch, int64_t rows);

  PolicyNetwork policy_;
  ValueNetwork value_;
  A2cConfig config_;
  std::shared_ptr<ReplicaGroup> replicas_;
  std::vector<at::Tensor> parameters_;
  std::unique_ptr<torch::optim::Optimizer> optimizer_;
  std::optional<FlatActorCritic> flat_;
  std::optional<FlatRmsprop> flat_rmsprop_;
  std::vector<float> d_log_probs_, d_values_;  // FlatUpdate's scratch
};

}  // namespace vantage

#endif  // VANTAGE_LEARNER_ALGORITHMS_A2C_A2C_UPDATER_H_
