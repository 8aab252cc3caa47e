#ifndef VANTAGE_LEARNER_BATCH_LINEAR_CRITIC_H_
#define VANTAGE_LEARNER_BATCH_LINEAR_CRITIC_H_

// rllab's linear feature baseline: the critic of EX2's code, and so of the
// paper's sparse-reward experiments, which left that code's critic as it
// was. V(s) = w . phi(s, t) with
//   phi = [clip(s, -10, 10), its squares, t/100, (t/100)^2, (t/100)^3, 1],
// t the step of its episode s is, and w refitted after every update by
// ridge least squares on the update's value targets (V + GAE).

#include <ATen/core/Tensor.h>

#include <cstdint>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "learner/ingest/rollout_stitcher.h"

namespace torch::serialize {
class InputArchive;
class OutputArchive;
}  // namespace torch::serialize

namespace vantage {

class ReplicaGroup;

class LinearCritic {
 public:
  static constexpr double kRidge = 1e-5;
  // Each retry multiplies the ridge by 10 (rllab's: five tries in all).
  static constexpr int kSolveAttempts = 5;

  explicit LinearCritic(int64_t observation_size);

  // phi of each row: `observations` [R, obs] (float), `episode_steps` [R]
  // (int64) -> [R, 2 obs + 4] double.
  static at::Tensor Features(const at::Tensor& observations,
                             const at::Tensor& episode_steps);

  // w . phi per row, float [R]; 0 until the first fit (as rllab's).
  at::Tensor Predict(const at::Tensor& features) const;

  // The values of every observation the advantage estimators need, in
  // CriticValuesOf's order: each rollout's T + 1 observations, then every
  // rollout's final observations of its truncated steps. Each rollout
  // must have its episode_steps (InvalidArgument otherwise).
  absl::StatusOr<at::Tensor> Values(const std::vector<Rollout>& rollouts) const;

  // Refits w to `targets` [R] over `features` [R, F], the normal equations
  // summed over the replicas so that every replica gets the same w. Returns
  // the new fit's mean squared error over every replica's rows. A system
  // that stays singular or non-finite through every ridge leaves w as it
  // was (FailedPrecondition).
  absl::StatusOr<double> Fit(const at::Tensor& features,
                             const at::Tensor& targets, ReplicaGroup& replicas);

  const at::Tensor& coefficients() const { return coefficients_; }
  // Another learner's w (rank 0's, a checkpoint's): refused by name unless
  // it holds 2 obs + 4 finite doubles; on error w is unchanged.
  absl::Status Restore(const at::Tensor& coefficients);
  void Save(torch::serialize::OutputArchive& archive) const;
  // A w of the wrong shape, dtype or with non-finite numbers is refused by
  // name; on error w is unchanged.
  absl::Status Load(torch::serialize::InputArchive& archive);

 private:
  at::Tensor coefficients_;  // [2 obs + 4] double
};

}  // namespace vantage

#endif  // VANTAGE_LEARNER_BATCH_LINEAR_CRITIC_H_
