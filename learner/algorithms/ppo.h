#ifndef VANTAGE_LEARNER_ALGORITHMS_PPO_H_
#define VANTAGE_LEARNER_ALGORITHMS_PPO_H_

#include <torch/optim/adam.h>

#include <memory>
#include <random>

#include "absl/status/status.h"
#include "common/nn/networks.h"

namespace vantage {

// Defaults of the paper's baselines setup for MuJoCo.
struct PpoConfig {
  int epochs = 10;
  int minibatches = 32;
  double clip = 0.2;
  double learning_rate = 3e-4;
  double max_grad_norm = 0.5;
  double value_coef = 0.5;
  double entropy_coef = 0.0;
  bool normalize_advantages = true;  // per minibatch, after rho mixing

  absl::Status Validate() const;
};

struct PpoStats {
  double policy_loss = 0.0;
  double value_loss = 0.0;
  double entropy = 0.0;
  double approx_kl = 0.0;
  double clip_fraction = 0.0;
};

// One PPO update over a batch: `epochs` passes of shuffled minibatches, a
// single Adam over the policy and value parameters, the gradient clipped to
// max_grad_norm. The policy loss takes the rho-mixed advantages, the value
// loss the normal targets V + GAE.
class PpoUpdater {
 public:
  PpoUpdater(PolicyNetwork policy, ValueNetwork value, const PpoConfig& config);

  // observations [B, obs] (normalised), actions [B, act], the others [B].
  // `learning_rate` overrides the configured one (linear decay).
  PpoStats Update(const at::Tensor& observations, const at::Tensor& actions,
                  const at::Tensor& behaviour_log_probs,
                  const at::Tensor& advantages, const at::Tensor& returns,
                  double learning_rate, std::mt19937_64& rng);

  torch::optim::Adam& optimizer() { return *optimizer_; }

 private:
  PolicyNetwork policy_;
  ValueNetwork value_;
  PpoConfig config_;
  std::vector<at::Tensor> parameters_;
  std::unique_ptr<torch::optim::Adam> optimizer_;
};

}  // namespace vantage

#endif  // VANTAGE_LEARNER_ALGORITHMS_PPO_H_
