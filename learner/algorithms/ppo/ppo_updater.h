#ifndef VANTAGE_LEARNER_ALGORITHMS_PPO_PPO_UPDATER_H_
#define VANTAGE_LEARNER_ALGORITHMS_PPO_PPO_UPDATER_H_

#include <memory>
#include <vector>

#include "absl/status/status.h"
#include "common/nn/networks.h"
#include "learner/algorithms/policy_updater.h"
#include "learner/algorithms/ppo/ppo_config.h"
#include "learner/parallel/replica_group.h"

namespace torch::optim {
class Adam;
}  // namespace torch::optim

namespace vantage {

// PPO: `epochs` passes of shuffled minibatches, one Adam (eps 1e-5) over
// the policy and value parameters, the gradient norm clipped. The ratio's
// denominator is the behaviour log-probability carried with the segment.
class PpoUpdater : public PolicyUpdater {
 public:
  static constexpr bool kOneOptimizer = true;

  // `replicas`: the data-parallel learners whose gradients are averaged.
  PpoUpdater(PolicyNetwork policy, ValueNetwork value, const PpoConfig& config,
             std::shared_ptr<ReplicaGroup> replicas = SoloReplicaGroup());
  ~PpoUpdater() override;

  AlgorithmStats Update(const UpdateBatch& batch, double progress,
                        std::mt19937_64& rng) override;
  void Save(torch::serialize::OutputArchive& archive) const override;
  absl::Status Load(torch::serialize::InputArchive& archive) override;

 private:
  PolicyNetwork policy_;
  ValueNetwork value_;
  PpoConfig config_;
  std::shared_ptr<ReplicaGroup> replicas_;
  std::vector<at::Tensor> parameters_;
  std::unique_ptr<torch::optim::Adam> optimizer_;
};

}  // namespace vantage

#endif  // VANTAGE_LEARNER_ALGORITHMS_PPO_PPO_UPDATER_H_
