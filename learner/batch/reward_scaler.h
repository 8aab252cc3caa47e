#ifndef VANTAGE_LEARNER_BATCH_REWARD_SCALER_H_
#define VANTAGE_LEARNER_BATCH_REWARD_SCALER_H_

#include <ATen/core/Tensor.h>

#include <cstdint>
#include <map>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "common/nn/running_mean_std.h"
#include "learner/ingest/rollout_stitcher.h"
#include "learner/parallel/replica_group.h"

namespace torch::serialize {
class InputArchive;
class OutputArchive;
}  // namespace torch::serialize

namespace vantage {

// Optional reward scaling as in the baselines' VecNormalize: rewards are
// divided by the running standard deviation of the discounted return
// R <- gamma * R + r (reset at every episode end), kept per env stream
// because each stream is its own sequence of episodes, then clipped.
class RewardScaler {
 public:
  RewardScaler(double gamma, double clip);

  // Folds the rollouts' discounted returns into the statistics (in rollout
  // order, continuing each (actor, slot) stream where it stopped), together
  // with every other replica's: all replicas scale by the same statistics.
  absl::Status Observe(const std::vector<Rollout>& rollouts,
                       ReplicaGroup& replicas);
  // rewards / sqrt(var + 1e-8), clipped to [-clip, clip].
  at::Tensor Scale(const at::Tensor& rewards) const;

  void Save(torch::serialize::OutputArchive& archive) const;
  absl::Status Load(torch::serialize::InputArchive& archive);

 private:
  double gamma_;
  double clip_;
  RunningMeanStd returns_;
  std::map<std::pair<int64_t, int64_t>, double> running_return_;
};

}  // namespace vantage

#endif  // VANTAGE_LEARNER_BATCH_REWARD_SCALER_H_
