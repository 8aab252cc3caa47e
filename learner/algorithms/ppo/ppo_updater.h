#ifndef VANTAGE_LEARNER_ALGORITHMS_PPO_PPO_UPDATER_H_
#define VANTAGE_LEARNER_ALGORITHMS_PPO_PPO_UPDATER_H_

#include <memory>
#include <vector>

#include "common/nn/networks.h"
#include "learner/algorithms/first_order_updater.h"
#include "learner/algorithms/ppo/ppo_config.h"
#include "learner/parallel/replica_group.h"

namespace vantage {

class PartsNormalizer;

// PPO: `epochs` passes of shuffled minibatches, one Adam (eps 1e-5) over
// the policy and value parameters, the gradient norm clipped. The ratio's
// denominator is the behaviour log-probability carried with the segment;
// for a lagged batch, PPO's decoupled objective (Hilton, Cobbe & Schulman
// 2021, "Batch size-invariance for policy optimization"): the ratio and its
// clipping against the policy as the update starts (the proximal policy),
// each advantage weighted by proximal / behaviour probability, so that a
// batch one version old gets the trust region a fresh one gets. MLP
// networks train through FlatActorCritic and FlatAdam.
class PpoUpdater : public FirstOrderUpdater {
 public:
  // `replicas`: the data-parallel learners whose gradients are averaged.
  PpoUpdater(PolicyNetwork policy, ValueNetwork value, const PpoConfig& config,
             std::shared_ptr<ReplicaGroup> replicas = SoloReplicaGroup(),
             bool autograd_only = false);
  ~PpoUpdater() override;

 private:
  // The batch with the proximal policy's log-probabilities as the ratio's
  // denominator and the advantages' importance weights (proximal over
  // behaviour probability); `batch` itself if it is not lagged.
  struct Decoupled {
    UpdateBatch batch;
    at::Tensor weights;  // [T*N], undefined when not lagged
  };
  Decoupled Decouple(const UpdateBatch& batch);
  // An epoch's minibatches: shuffled rows (`order` is scratch of the
  // batch's size), or for a recurrent policy shuffled whole chunks.
  std::vector<ChunkMinibatch> EpochMinibatches(const UpdateBatch& batch,
                                               std::vector<int64_t>& order,
                                               int64_t minibatch,
                                               std::mt19937_64& rng);
  AlgorithmStats AutogradUpdate(const UpdateBatch& batch,
                                std::mt19937_64& rng) override;
  AlgorithmStats FlatUpdate(const UpdateBatch& batch,
                            std::mt19937_64& rng) override;
  // One flat minibatch (`part` of the epoch's advantage normaliser, if
  // any).
  AlgorithmStats FlatMinibatch(const FlatRows& rows, const at::Tensor& weights,
                               const ChunkMinibatch& minibatch,
                               PartsNormalizer* normalizer, size_t part);

  PpoConfig config_;
  // Scratch of FlatUpdate: one minibatch's importance weights.
  std::vector<float> weights_;
};

}  // namespace vantage

#endif  // VANTAGE_LEARNER_ALGORITHMS_PPO_PPO_UPDATER_H_
