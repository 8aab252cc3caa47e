#ifndef VANTAGE_LEARNER_PARALLEL_REPLICA_REDUCTIONS_H_
#define VANTAGE_LEARNER_PARALLEL_REPLICA_REDUCTIONS_H_

// What the learner computes over the global batch of a data-parallel run
// (every replica's rollouts), built on ReplicaGroup's collectives. With a
// group of one each helper computes exactly what a single learner always
// did, operation for operation.

#include <ATen/core/Tensor.h>

#include <vector>

#include "absl/status/status.h"
#include "learner/parallel/replica_group.h"

namespace vantage {

class RunningMeanStd;

// Replaces every parameter's gradient by its mean over the replicas (one
// flat collective); a parameter without a gradient counts as zero. Every
// replica must hold equally many samples for this to be the gradient of the
// global batch's mean loss.
void AverageGradients(ReplicaGroup& group,
                      const std::vector<at::Tensor>& parameters);

// The mean of `value` over the replicas (same shape everywhere).
at::Tensor AverageAcrossReplicas(ReplicaGroup& group, const at::Tensor& value);

// Sums of `values` over the replicas, in double precision.
std::vector<double> SumAcrossReplicas(ReplicaGroup& group,
                                      std::vector<double> values);

// (x - mean) / (std + 1e-8) with the mean and the (unbiased) standard
// deviation of every replica's `x` together.
at::Tensor NormalizeAcrossReplicas(ReplicaGroup& group, const at::Tensor& x);

// The same for several parts of `x` at once (PPO's minibatches of one
// epoch: part i of every replica together is one global minibatch), with
// one collective for all parts.
class PartsNormalizer {
 public:
  // `parts`: index tensors into x (dim 0).
  PartsNormalizer(ReplicaGroup& group, const at::Tensor& x,
                  const std::vector<at::Tensor>& parts);
  // `values` (part `part` of x) normalised with that part's statistics.
  at::Tensor Normalize(size_t part, const at::Tensor& values) const;
  // The same on `count` floats in place (one replica: their own
  // statistics, computed in double).
  void NormalizeInPlace(size_t part, float* values, int64_t count) const;

 private:
  bool local_;  // one replica: each part's own statistics, in its dtype
  std::vector<double> means_;
  std::vector<double> stds_;
};

// Folds every replica's `rows` ([B, size]) into `stats`, as one batch. A
// non-finite value or a wrong size on any replica leaves every replica's
// statistics unchanged and returns InvalidArgument on all of them.
absl::Status UpdateAcrossReplicas(ReplicaGroup& group, RunningMeanStd& stats,
                                  const at::Tensor& rows);

}  // namespace vantage

#endif  // VANTAGE_LEARNER_PARALLEL_REPLICA_REDUCTIONS_H_
