#ifndef VANTAGE_LEARNER_ALGORITHMS_GRADIENT_STEP_H_
#define VANTAGE_LEARNER_ALGORITHMS_GRADIENT_STEP_H_

// Pieces the first-order actor-critic algorithms (PPO, A2C) share.

#include <ATen/core/Tensor.h>

#include <optional>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "common/nn/networks.h"
#include "learner/algorithms/flat_actor_critic.h"
#include "learner/algorithms/policy_updater.h"
#include "learner/parallel/replica_group.h"

namespace torch::optim {
class Optimizer;
}  // namespace torch::optim
namespace torch::serialize {
class InputArchive;
class OutputArchive;
}  // namespace torch::serialize

namespace vantage {

// 0.5 * mean((V(s) - target)^2).
at::Tensor ValueLoss(ValueNetworkImpl& value, const at::Tensor& observations,
                     const at::Tensor& targets);

// Zeroes the gradients, backpropagates `loss`, averages the gradients over
// `replicas`, clips the global gradient norm of `parameters` to
// `max_grad_norm` and steps. Returns the norm before clipping (the same on
// every replica).
double GradientStep(torch::optim::Optimizer& optimizer,
                    const std::vector<at::Tensor>& parameters,
                    const at::Tensor& loss, double max_grad_norm,
                    ReplicaGroup& replicas);

// The mean of a flat gradient array of `size` floats over `replicas` (one
// collective; nothing with one replica).
void AverageFlatGradient(float* gradients, int64_t size,
                         ReplicaGroup& replicas);

// GradientStep's averaging and clipping for a flat gradient array of
// `size` floats (FlatActorCritic's): the mean over `replicas` (one
// collective), then scaled as clip_grad_norm_ scales to `max_grad_norm`.
// Returns the norm before clipping.
double AverageAndClipFlatGradient(float* gradients, int64_t size,
                                  double max_grad_norm, ReplicaGroup& replicas);

// The flat networks `algorithm` (its name, for the log) trains `policy` and
// `value` with, or none, after one line on stderr saying why, when they
// cannot run there (or `autograd_only`).
std::optional<FlatActorCritic> MakeFlatActorCritic(
    PolicyNetworkImpl& policy, ValueNetworkImpl& value,
    const std::vector<at::Tensor>& parameters, const char* algorithm,
    bool autograd_only);

// `values` as a contiguous float tensor of `rows` rows.
at::Tensor FloatRows(const at::Tensor& values, int64_t rows);

// `rows` rows of `width` floats of `source` picked by `index` into `out`.
void GatherRows(const float* source, int64_t width, const int64_t* index,
                int64_t rows, std::vector<float>& out);

// Sets every parameter group's learning rate.
void SetLearningRate(torch::optim::Optimizer& optimizer, double learning_rate);

// Averages per-minibatch statistics (a NaN field stays NaN), except
// max_gradient_norm, which is the largest (NaN if any was).
class MeanStats {
 public:
  void Add(const AlgorithmStats& stats);
  AlgorithmStats Mean() const;

 private:
  AlgorithmStats sum_;
  int64_t count_ = 0;
};

// Checkpoint helpers: an optimiser's state under `key`. Loading a state
// that does not fit the optimiser (missing, or a tensor whose shape is not
// its parameter's) is an InvalidArgument error and leaves the optimiser as
// it was.
void SaveOptimizer(const torch::optim::Optimizer& optimizer,
                   const std::string& key,
                   torch::serialize::OutputArchive& archive);
absl::Status LoadOptimizer(torch::optim::Optimizer& optimizer,
                           const std::string& key,
                           torch::serialize::InputArchive& archive);

}  // namespace vantage

#endif  // VANTAGE_LEARNER_ALGORITHMS_GRADIENT_STEP_H_
