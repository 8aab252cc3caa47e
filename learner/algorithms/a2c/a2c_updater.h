#ifndef VANTAGE_LEARNER_ALGORITHMS_A2C_A2C_UPDATER_H_
#define VANTAGE_LEARNER_ALGORITHMS_A2C_A2C_UPDATER_H_

#include <memory>
#include <vector>

#include "absl/status/status.h"
#include "common/nn/networks.h"
#include "learner/algorithms/a2c/a2c_config.h"
#include "learner/algorithms/policy_updater.h"
#include "learner/parallel/replica_group.h"

namespace torch::optim {
class Optimizer;
}  // namespace torch::optim

namespace vantage {

// A2C: per minibatch one RMSProp step (a2c.rmsprop's arithmetic) on
// -mean(log pi(a|s) A) + value_coef * value loss - entropy_coef * entropy.
class A2cUpdater : public PolicyUpdater {
 public:
  static constexpr bool kOneOptimizer = true;

  // `replicas`: the data-parallel learners whose gradients are averaged.
  A2cUpdater(PolicyNetwork policy, ValueNetwork value, const A2cConfig& config,
             std::shared_ptr<ReplicaGroup> replicas = SoloReplicaGroup());
  ~A2cUpdater() override;

  // The batch's horizon must be a multiple of steps_per_minibatch; the
  // minibatches are its consecutive time slices, oldest first.
  AlgorithmStats Update(const UpdateBatch& batch, double progress,
                        std::mt19937_64& rng) override;
  void Save(torch::serialize::OutputArchive& archive) const override;
  absl::Status Load(torch::serialize::InputArchive& archive) override;

 private:
  PolicyNetwork policy_;
  ValueNetwork value_;
  A2cConfig config_;
  std::shared_ptr<ReplicaGroup> replicas_;
  std::vector<at::Tensor> parameters_;
  std::unique_ptr<torch::optim::Optimizer> optimizer_;
};

}  // namespace vantage

#endif  // VANTAGE_LEARNER_ALGORITHMS_A2C_A2C_UPDATER_H_
