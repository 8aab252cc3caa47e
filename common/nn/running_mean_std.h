#ifndef VANTAGE_COMMON_NN_RUNNING_MEAN_STD_H_
#define VANTAGE_COMMON_NN_RUNNING_MEAN_STD_H_

#include <ATen/core/Tensor.h>

#include <cstdint>

#include "absl/status/status.h"

namespace vantage {

// Running mean and variance of vectors, merged batch by batch with Chan et
// al.'s parallel formula in double precision. The observation normaliser
// (owned by the learner, shipped with the weights, checkpointed) and the
// return-based reward scaler are built on it.
class RunningMeanStd {
 public:
  // `initial_count` is the weight of the initial (mean 0, variance 1)
  // estimate, which keeps the first normalisations finite.
  explicit RunningMeanStd(int64_t size, double initial_count = 1e-4);

  // batch: [B, size] (or [size]); rejects wrong sizes and non-finite values
  // without touching the statistics.
  absl::Status Update(const at::Tensor& batch);
  // Folds in a batch given by its moments: `count` rows with per-element
  // `mean` and (population) `var`, double [size]. Update() is this on the
  // batch's own moments; data-parallel learners merge moments summed
  // across replicas.
  absl::Status Merge(double count, const at::Tensor& mean,
                     const at::Tensor& var);

  // (x - mean) / sqrt(var + 1e-8), clipped to [-clip, clip], in x's dtype.
  at::Tensor Normalize(const at::Tensor& x, double clip) const;

  int64_t size() const { return mean_.size(0); }
  double count() const { return count_; }
  const at::Tensor& mean() const { return mean_; }  // double [size]
  const at::Tensor& var() const { return var_; }    // double [size]

  // For checkpoints: replaces the state after checking it.
  absl::Status Restore(double count, const at::Tensor& mean,
                       const at::Tensor& var);

 private:
  double count_;
  at::Tensor mean_;
  at::Tensor var_;
};

}  // namespace vantage

#endif  // VANTAGE_COMMON_NN_RUNNING_MEAN_STD_H_
