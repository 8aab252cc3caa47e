#ifndef VANTAGE_LEARNER_ALGORITHMS_TRPO_TRPO_UPDATER_H_
#define VANTAGE_LEARNER_ALGORITHMS_TRPO_TRPO_UPDATER_H_

#include <memory>
#include <vector>

#include "absl/status/status.h"
#include "common/nn/networks.h"
#include "learner/algorithms/policy_updater.h"
#include "learner/algorithms/trpo/trpo_config.h"
#include "learner/parallel/replica_group.h"

namespace torch::optim {
class Adam;
}  // namespace torch::optim

namespace vantage {

// TRPO: the natural-gradient direction by conjugate gradient on
// Fisher-vector products (Hessian of the mean KL, damped), scaled to the
// trust region's edge, then a backtracking line search that accepts the
// first step with mean KL(old || new) <= max_kl and a positive improvement
// of the surrogate; if none qualifies the policy stays as it was.
class TrpoUpdater : public PolicyUpdater {
 public:
  static constexpr bool kOneOptimizer = false;

  // `replicas`: the data-parallel learners whose gradients are averaged.
  TrpoUpdater(PolicyNetwork policy, ValueNetwork value,
              const TrpoConfig& config,
              std::shared_ptr<ReplicaGroup> replicas = SoloReplicaGroup());
  ~TrpoUpdater() override;

  AlgorithmStats Update(const UpdateBatch& batch, double progress,
                        std::mt19937_64& rng) override;
  void Save(torch::serialize::OutputArchive& archive) const override;
  absl::Status Load(torch::serialize::InputArchive& archive) override;

 private:
  // What a policy step compares the moved policy against.
  struct PolicyStepInputs {
    const UpdateBatch& batch;
    const at::Tensor& advantages;
    at::Tensor old_output;
    at::Tensor old_log_std;  // undefined for a discrete policy
  };

  // Returns the accepted step's mean KL (0 if the policy did not move).
  double PolicyStep(const UpdateBatch& batch, const at::Tensor& advantages,
                    double& surrogate_after);
  // Importance-weighted against the policy that acted (the actors' version
  // may lag the learner's).
  // The policy's outputs on the batch, scored under its action masks.
  at::Tensor Outputs(const UpdateBatch& batch);
  at::Tensor Surrogate(const PolicyStepInputs& step);
  at::Tensor MeanKl(const PolicyStepInputs& step);
  at::Tensor FisherProduct(const PolicyStepInputs& step, const at::Tensor& v);
  // To the trust region's edge; undefined when the curvature along the
  // direction is not positive and finite.
  at::Tensor NaturalGradientStep(const PolicyStepInputs& step,
                                 const at::Tensor& objective);
  // Tries ever halved fractions of `full_step`; returns the accepted one's
  // mean KL, or restores the parameters and returns 0.
  double LineSearch(const PolicyStepInputs& step, const at::Tensor& full_step,
                    double objective_before, double& surrogate_after);
  double FitValue(const UpdateBatch& batch, std::mt19937_64& rng);

  TrpoConfig config_;
  std::vector<at::Tensor> policy_parameters_;
  std::vector<at::Tensor> value_parameters_;
  std::unique_ptr<torch::optim::Adam> value_optimizer_;
};

}  // namespace vantage

#endif  // VANTAGE_LEARNER_ALGORITHMS_TRPO_TRPO_UPDATER_H_
