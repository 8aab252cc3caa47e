#ifndef VANTAGE_LEARNER_ALGORITHMS_PPO_H_
#define VANTAGE_LEARNER_ALGORITHMS_PPO_H_

#include <memory>
#include <vector>

#include "absl/status/status.h"
#include "common/nn/networks.h"
#include "learner/algorithms/policy_updater.h"

namespace torch::optim {
class Adam;
}  // namespace torch::optim

namespace vantage {

// Defaults of the paper's baselines setup for MuJoCo.
struct PpoConfig {
  int epochs = 10;
  int minibatches = 32;
  double clip = 0.2;
  double learning_rate = 3e-4;  // decays linearly to 0 over the run
  double max_grad_norm = 0.5;
  double value_coef = 0.5;
  double entropy_coef = 0.0;
  bool normalize_advantages = true;  // per minibatch, after rho mixing

  absl::Status Validate() const;
};

// PPO: `epochs` passes of shuffled minibatches, one Adam (eps 1e-5) over
// the policy and value parameters, the gradient norm clipped. The ratio's
// denominator is the behaviour log-probability carried with the segment.
class PpoUpdater : public PolicyUpdater {
 public:
  PpoUpdater(PolicyNetwork policy, ValueNetwork value, const PpoConfig& config);
  ~PpoUpdater() override;

  AlgorithmStats Update(const UpdateBatch& batch, double progress,
                        std::mt19937_64& rng) override;
  void Save(torch::serialize::OutputArchive& archive) const override;
  absl::Status Load(torch::serialize::InputArchive& archive) override;

 private:
  PolicyNetwork policy_;
  ValueNetwork value_;
  PpoConfig config_;
  std::vector<at::Tensor> parameters_;
  std::unique_ptr<torch::optim::Adam> optimizer_;
};

}  // namespace vantage

#endif  // VANTAGE_LEARNER_ALGORITHMS_PPO_H_
