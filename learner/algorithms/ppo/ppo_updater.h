#ifndef VANTAGE_LEARNER_ALGORITHMS_PPO_PPO_UPDATER_H_
#define VANTAGE_LEARNER_ALGORITHMS_PPO_PPO_UPDATER_H_

#include <memory>
#include <optional>
#include <vector>

#include "absl/status/status.h"
#include "common/nn/networks.h"
#include "learner/algorithms/flat_actor_critic.h"
#include "learner/algorithms/flat_adam.h"
#include "learner/algorithms/policy_updater.h"
#include "learner/algorithms/ppo/ppo_config.h"
#include "learner/parallel/replica_group.h"

namespace torch::optim {
class Adam;
}  // namespace torch::optim

namespace vantage {

// PPO: `epochs` passes of shuffled minibatches, one Adam (eps 1e-5) over
// the policy and value parameters, the gradient norm clipped. The ratio's
// denominator is the behaviour log-probability carried with the segment;
// for a lagged batch, PPO's decoupled objective (Hilton, Cobbe & Schulman
// 2021, "Batch size-invariance for policy optimization"): the ratio and its
// clipping against the policy as the update starts (the proximal policy),
// each advantage weighted by proximal / behaviour probability, so that a
// batch one version old gets the trust region a fresh one gets. MLP
// networks train through FlatActorCritic and FlatAdam (the same
// update without autograd, several times faster); convolutional ones, or
// every network when `autograd_only`, through LibTorch's autograd.
class PpoUpdater : public PolicyUpdater {
 public:
  static constexpr bool kOneOptimizer = true;

  // `replicas`: the data-parallel learners whose gradients are averaged.
  PpoUpdater(PolicyNetwork policy, ValueNetwork value, const PpoConfig& config,
             std::shared_ptr<ReplicaGroup> replicas = SoloReplicaGroup(),
             bool autograd_only = false);
  ~PpoUpdater() override;

  AlgorithmStats Update(const UpdateBatch& batch, double progress,
                        std::mt19937_64& rng) override;
  void Save(torch::serialize::OutputArchive& archive) const override;
  absl::Status Load(torch::serialize::InputArchive& archive) override;

  // Whether updates bypass autograd.
  bool flat() const { return flat_.has_value(); }

 private:
  // The batch with the proximal policy's log-probabilities as the ratio's
  // denominator and the advantages' importance weights (proximal over
  // behaviour probability); `batch` itself if it is not lagged.
  struct Decoupled {
    UpdateBatch batch;
    at::Tensor weights;  // [T*N], undefined when not lagged
  };
  Decoupled Decouple(const UpdateBatch& batch);
  AlgorithmStats AutogradUpdate(const Decoupled& batch, std::mt19937_64& rng);
  AlgorithmStats FlatUpdate(const Decoupled& batch, std::mt19937_64& rng);

  PolicyNetwork policy_;
  ValueNetwork value_;
  PpoConfig config_;
  std::shared_ptr<ReplicaGroup> replicas_;
  std::vector<at::Tensor> parameters_;
  std::unique_ptr<torch::optim::Adam> optimizer_;
  std::optional<FlatActorCritic> flat_;
  std::optional<FlatAdam> flat_adam_;
  // Scratch of FlatUpdate: one minibatch's rows.
  std::vector<float> inputs_, actions_, behaviour_, advantages_, returns_,
      weights_, d_log_probs_, d_values_;
};

}  // namespace vantage

#endif  // VANTAGE_LEARNER_ALGORITHMS_PPO_PPO_UPDATER_H_
