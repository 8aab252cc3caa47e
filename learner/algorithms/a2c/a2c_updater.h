#ifndef VANTAGE_LEARNER_ALGORITHMS_A2C_A2C_UPDATER_H_
#define VANTAGE_LEARNER_ALGORITHMS_A2C_A2C_UPDATER_H_

#include <memory>

#include "common/nn/networks.h"
#include "learner/algorithms/a2c/a2c_config.h"
#include "learner/algorithms/first_order_updater.h"
#include "learner/parallel/replica_group.h"

namespace vantage {

// A2C: per minibatch one RMSProp step (a2c.rmsprop's arithmetic) on
// -mean(log pi(a|s) A) + value_coef * value loss - entropy_coef * entropy.
// MLP networks train through FlatActorCritic and FlatRmsprop.
class A2cUpdater : public FirstOrderUpdater {
 public:
  // `replicas`: the data-parallel learners whose gradients are averaged.
  // The batch's horizon must be a multiple of steps_per_minibatch; the
  // minibatches are its consecutive time slices, oldest first.
  A2cUpdater(PolicyNetwork policy, ValueNetwork value, const A2cConfig& config,
             std::shared_ptr<ReplicaGroup> replicas = SoloReplicaGroup(),
             bool autograd_only = false);
  ~A2cUpdater() override;

 private:
  AlgorithmStats AutogradUpdate(const UpdateBatch& batch,
                                std::mt19937_64& rng) override;
  AlgorithmStats FlatUpdate(const UpdateBatch& batch,
                            std::mt19937_64& rng) override;
  // Rows of one minibatch: steps_per_minibatch steps of every stream.
  int64_t MinibatchRows(const UpdateBatch& batch) const {
    return config_.steps_per_minibatch * batch.streams;
  }

  A2cConfig config_;
};

}  // namespace vantage

#endif  // VANTAGE_LEARNER_ALGORITHMS_A2C_A2C_UPDATER_H_
