#ifndef VANTAGE_LEARNER_ALGORITHMS_A2C_H_
#define VANTAGE_LEARNER_ALGORITHMS_A2C_H_

#include <memory>
#include <vector>

#include "absl/status/status.h"
#include "common/nn/networks.h"
#include "learner/algorithms/policy_updater.h"

namespace torch::optim {
class RMSprop;
}  // namespace torch::optim

namespace vantage {

// Defaults of the baselines' A2C the paper builds on.
struct A2cConfig {
  int steps_per_minibatch = 5;  // A2C's rollout length
  // The paper's path-ensemble trick: rollouts of steps_per_minibatch * n
  // steps (longer paths for the k-step estimates), updated as n
  // consecutive minibatches of steps_per_minibatch steps each. n = 1 is the
  // original A2C.
  int minibatches = 1;
  double learning_rate = 7e-4;  // decays linearly to 0 over the run
  double rmsprop_alpha = 0.99;
  double rmsprop_eps = 1e-5;
  double max_grad_norm = 0.5;
  double value_coef = 0.5;
  double entropy_coef = 0.01;

  int64_t horizon() const {
    return static_cast<int64_t>(steps_per_minibatch) * minibatches;
  }
  absl::Status Validate() const;
};

// A2C: per minibatch one RMSProp step on
// -mean(log pi(a|s) A) + value_coef * value loss - entropy_coef * entropy.
class A2cUpdater : public PolicyUpdater {
 public:
  A2cUpdater(PolicyNetwork policy, ValueNetwork value, const A2cConfig& config);
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
  std::vector<at::Tensor> parameters_;
  std::unique_ptr<torch::optim::RMSprop> optimizer_;
};

}  // namespace vantage

#endif  // VANTAGE_LEARNER_ALGORITHMS_A2C_H_
