#ifndef VANTAGE_LEARNER_BATCH_BATCH_PREPARER_H_
#define VANTAGE_LEARNER_BATCH_BATCH_PREPARER_H_

// The learner's second stage: a batch of rollouts becomes what the
// algorithm trains on. The exploration bonus shapes the rewards, the
// current critic values every observation (a time limit ends the return
// instead where the run says so), the rewards are scaled, the
// advantages (GAE and the rho-mixed path-ensemble estimate) computed, and
// the observations normalised.

#include <cstdint>
#include <random>
#include <vector>

#include "absl/status/statusor.h"
#include "common/advantage/advantage.h"
#include "learner/algorithms/update_batch.h"
#include "learner/batch/training_batch.h"
#include "learner/exploration/exploration_stats.h"
#include "learner/ingest/rollout_stitcher.h"
#include "learner/learner_config.h"

namespace vantage {

class Ex2Bonus;
class LinearCritic;
class ReplicaGroup;
class RewardScaler;
class RunningMeanStd;
class ValueNetworkImpl;

// What an update's optimisation works on: the batch, its advantages, the
// algorithm's view of both, and how stale each rollout was.
struct PreparedBatch {
  ExplorationStats exploration;
  TrainingBatch batch;
  Advantages advantages;
  UpdateBatch update;
  // How many versions behind the updating one each rollout's oldest step
  // was acted.
  std::vector<int64_t> lags;
};

class BatchPreparer {
 public:
  // Everything referenced belongs to the learner and must outlive this.
  // `exploration` may be null (a run without a bonus); the reward scaler
  // is used only when the config scales rewards; a `linear_critic` values
  // the states instead of `value` (null: the value network does).
  BatchPreparer(const LearnerConfig& config, ValueNetworkImpl& value,
                const RunningMeanStd& normalizer, RewardScaler& reward_scaler,
                Ex2Bonus* exploration, ReplicaGroup& replicas,
                const LinearCritic* linear_critic = nullptr);

  // The batch of `rollouts` for the policy at `version`; the rho masks
  // draw from `rng`. The reward scaler and the exploration model absorb
  // the batch (the update's guard undoes it if the update fails).
  absl::StatusOr<PreparedBatch> Prepare(std::vector<Rollout>& rollouts,
                                        int64_t version, std::mt19937_64& rng);

 private:
  // The critic's values in AssembleBatch's order (a feed-forward one).
  at::Tensor Values(const std::vector<Rollout>& rollouts) const;
  // The batch, its values from the current critic; a recurrent one's also
  // marks episode starts and the states its chunks start from.
  absl::StatusOr<TrainingBatch> Assemble(
      const std::vector<Rollout>& rollouts) const;
  // Raw observations as the networks take them.
  at::Tensor Normalised(const at::Tensor& observations) const;

  const LearnerConfig& config_;
  ValueNetworkImpl& value_;
  const RunningMeanStd& normalizer_;
  RewardScaler& reward_scaler_;
  Ex2Bonus* exploration_;
  ReplicaGroup& replicas_;
  const LinearCritic* linear_critic_;
};

}  // namespace vantage

#endif  // VANTAGE_LEARNER_BATCH_BATCH_PREPARER_H_
