#ifndef VANTAGE_LEARNER_EXPLORATION_EX2_BONUS_H_
#define VANTAGE_LEARNER_EXPLORATION_EX2_BONUS_H_

// EX2's exploration bonus on the learner, in the order of its reference
// code (parallel_trpo/batch_polopt.py, models/exemplar.py): once the pool
// has seen replay_min states, each batch first fits the exemplar model
// (positives (x, x) drawn from the batch, negatives (x, x') with x' from
// the pool), then the batch joins the pool, then every step's reward gains
// bonus_coeff x (b - median b) with b = -log p(x) from the fitted model.
// The critic and the advantage estimators see the shaped rewards; the
// episode returns the actors report stay the environment's own.

#include <ATen/core/Generator.h>
#include <ATen/core/Tensor.h>

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "common/env/environment.h"
#include "learner/algorithms/flat_adam.h"
#include "learner/exploration/ex2_config.h"
#include "learner/exploration/exemplar_model.h"
#include "learner/exploration/exploration_stats.h"
#include "learner/exploration/flat_exemplar_model.h"
#include "learner/exploration/replay_pool.h"
#include "learner/ingest/rollout_stitcher.h"
#include "learner/parallel/replica_group.h"

namespace torch::optim {
class Adam;
}  // namespace torch::optim
namespace torch::serialize {
class InputArchive;
class OutputArchive;
}  // namespace torch::serialize

namespace vantage {

// How the model is fitted. kFlat (the default): FlatExemplarModel's
// gradients and FlatAdam's steps, in a few loops over flat arrays;
// kAutograd: autograd's gradients and FlatAdam's steps; kTorch: autograd
// and torch::optim::Adam (the same arithmetic, a dozen operators per
// parameter tensor). The last two for tests and benchmarks. A
// convolutional model fits as kAutograd when kFlat is asked.
enum class Ex2Fit { kFlat, kAutograd, kTorch };

class Ex2Bonus {
 public:
  // The model's initial weights come from LibTorch's global generator; its
  // sampling from its own, seeded by `seed`. With `replicas`, gradients
  // are averaged over them (every replica must start from the same
  // weights, which the learner broadcasts).
  Ex2Bonus(const Ex2Config& config, const EnvSpec& spec, uint64_t seed,
           std::shared_ptr<ReplicaGroup> replicas, Ex2Fit fit = Ex2Fit::kFlat);
  ~Ex2Bonus();

  // Fits the model and adds the bonus to the rollouts' rewards (see
  // above). The rollouts' states join the pool only at Commit, so that an
  // update that is rolled back leaves the pool as it was.
  ExplorationStats ShapeRewards(std::vector<Rollout>& rollouts);
  void Commit();

  std::vector<at::Tensor> parameters() const;
  ExemplarModelImpl& model() { return *model_; }
  const ReplayPool& pool() const { return pool_; }

  // What ShapeRewards changes but the pool: the model, its optimiser, the
  // generator and whether it has fitted before (for rolling back).
  // Entries named `prefix`.model.*, .optimizer, .generator and .fitted.
  void SaveModelState(torch::serialize::OutputArchive& archive,
                      const std::string& prefix) const;
  absl::Status LoadModelState(torch::serialize::InputArchive& archive,
                              const std::string& prefix);
  // All of it, pool included (checkpoints). On error the object is half
  // loaded: the learner being loaded is discarded.
  // With the pool as `prefix`.pool.*: flat entries beside the learner's
  // own, so that checkpoint checks and fuzzing reach every one.
  void Save(torch::serialize::OutputArchive& archive,
            const std::string& prefix) const;
  absl::Status Load(torch::serialize::InputArchive& archive,
                    const std::string& prefix);

  // The model's inputs for the rollouts' steps: [sum T, width], states
  // with the actions when use_actions (one-hot if discrete; continuous
  // ones clipped to the bounds and scaled to [-1, 1]).
  at::Tensor Inputs(const std::vector<Rollout>& rollouts) const;

 private:
  // The rollouts' byte observations as the pool keeps them, [steps, obs]
  // uint8, in Inputs' row order.
  at::Tensor ByteRows(const std::vector<Rollout>& rollouts) const;
  // One fit step on a batch of positives (its loss and accuracy), its
  // gradients averaged over the replicas.
  std::pair<double, double> FitStep(const at::Tensor& positives,
                                    const at::Tensor& negatives);
  // autograd's gradients of `loss` into flat_gradients_ (kAutograd), or
  // its step (kTorch).
  void AutogradStep(const at::Tensor& loss);

  Ex2Config config_;
  EnvSpec spec_;
  std::shared_ptr<ReplicaGroup> replicas_;
  ExemplarModel model_{nullptr};
  std::unique_ptr<torch::optim::Adam> optimizer_;
  // With FlatAdam, the model's parameters are views of one flat tensor,
  // which it steps in place, from one array of gradients (FlatExemplarModel
  // writes them there; autograd's are gathered). optimizer_ then only
  // carries the state into checkpoints.
  at::Tensor flat_parameters_;
  std::vector<float> flat_gradients_;
  std::optional<FlatAdam> flat_adam_;
  std::optional<FlatExemplarModel> flat_model_;
  at::Generator generator_;
  ReplayPool pool_;
  bool fitted_ = false;
  // Pool rows of the batch shaped last (its inputs, or its bytes for a
  // byte pool), until Commit.
  at::Tensor pending_;
};

}  // namespace vantage

#endif  // VANTAGE_LEARNER_EXPLORATION_EX2_BONUS_H_
