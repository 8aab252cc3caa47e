#ifndef VANTAGE_LEARNER_LEARNER_CORE_H_
#define VANTAGE_LEARNER_LEARNER_CORE_H_

#include <cstdint>
#include <deque>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "common/env/environment.h"
#include "common/nn/networks.h"
#include "common/nn/policy_weights.h"
#include "common/nn/running_mean_std.h"
#include "common/rollout/segment_queue.h"
#include "learner/algorithms/algorithm.h"
#include "learner/batch/batch_preparer.h"
#include "learner/batch/reward_scaler.h"
#include "learner/ingest/segment_intake.h"
#include "learner/learner_config.h"
#include "learner/parallel/replica_group.h"
#include "learner/update/update_stats.h"
#include "learner/update/update_totals.h"

namespace vantage {

class Ex2Bonus;
class LinearCritic;
class UpdateGuard;

// Consumes segments, stitches rollouts, evaluates the critic, estimates
// advantages (GAE + the biased path ensemble, rho-mixed), runs the
// configured algorithm (PPO, A2C or TRPO) and versions the weights. Knows
// nothing of how segments travel.
class LearnerCore {
 public:
  // Seeds LibTorch's global generator with config.seed, so the initial
  // networks are reproducible. With `replicas` of more than one learner,
  // every replica starts from rank 0's networks and statistics (Create
  // returns once all have joined) and each update averages gradients and
  // statistics over them; rank r draws its minibatches and rho masks from
  // ReplicaSeed(seed, r).
  static absl::StatusOr<std::unique_ptr<LearnerCore>> Create(
      const LearnerConfig& config,
      std::shared_ptr<ReplicaGroup> replicas = SoloReplicaGroup());

  ~LearnerCore();

  PolicyWeights CurrentWeights();
  // Blocks on `source` until a batch is complete, then updates. A replica
  // lost during the update leaves this learner as it was before it and
  // returns Unavailable.
  absl::StatusOr<UpdateStats> RunUpdate(SegmentSource& source);

  // Frees the stitching state of an actor that is gone (its registration
  // expired); rollouts it already completed still train.
  void ForgetActor(int64_t actor_id) { intake_.ForgetActor(actor_id); }
  // Who decides the batch's size (null: the config's rollouts_per_batch);
  // it must outlive the updates.
  void SetBatchPlan(BatchPlan* plan) { intake_.SetPlan(plan); }
  const SegmentIntake& intake() const { return intake_; }
  const RolloutStitcher& stitcher() const { return intake_.stitcher(); }
  // Steps held for later batches: partial rollouts and complete ones that
  // wait for their batch.
  int64_t buffered_steps() const { return intake_.buffered_steps(); }

  // Returns of the episodes reported by consumed segments, newest last
  // (at most 100 kept).
  const std::deque<double>& recent_returns() const {
    return intake_.recent_returns();
  }
  // Mean of recent_returns(); NaN before the first episode ends.
  double MeanRecentReturn() const;
  // The exploration bonus, or null in a run without one.
  const Ex2Bonus* exploration() const { return exploration_.get(); }
  int64_t policy_version() const { return version_; }
  int64_t env_steps() const { return env_steps_; }
  const LearnerConfig& config() const { return config_; }

  // Everything later updates depend on: both networks, the optimiser
  // state, the exploration model and its pool, the observation normaliser,
  // the reward scaler, the random
  // generator, the version and counters, the recent returns and the
  // environment spec. Rollouts still being stitched are not included (a
  // resumed learner starts every stream afresh).
  void Save(torch::serialize::OutputArchive& archive) const;
  // Creates a learner from `config` and the state `archive` holds; any
  // missing or mismatching entry is an InvalidArgument error naming it.
  // Replicas all load the same checkpoint (rank 0's); ranks other than 0
  // then reseed their generator from ReplicaSeed(seed, rank) + version.
  static absl::StatusOr<std::unique_ptr<LearnerCore>> Load(
      const LearnerConfig& config, torch::serialize::InputArchive& archive,
      std::shared_ptr<ReplicaGroup> replicas = SoloReplicaGroup());
  const ReplicaGroup& replicas() const { return *replicas_; }

 private:
  LearnerCore(const LearnerConfig& config,
              std::shared_ptr<ReplicaGroup> replicas);
  // A new learner whose networks are initialised from config.seed.
  static std::unique_ptr<LearnerCore> Construct(
      const LearnerConfig& config, std::shared_ptr<ReplicaGroup> replicas);
  // What Load reads into a new learner: the networks, the optimiser,
  // reward scaler, normaliser and exploration states; then the generator,
  // counters and recent returns.
  absl::Status LoadModels(torch::serialize::InputArchive& archive);
  absl::Status LoadLinearCritic(torch::serialize::InputArchive& archive);
  absl::Status LoadCounters(torch::serialize::InputArchive& archive);
  // Rank 0's networks, normaliser and counters on every replica; an error
  // if this replica's version differs from rank 0's.
  absl::Status SynchroniseReplicas();
  // The update once its batch is complete, under a guard that undoes it on
  // any error or a rollback: the batch and its advantages (the preparer),
  // the algorithm's optimisation, the statistics summed over the replicas,
  // and the new version committed (Commit).
  absl::StatusOr<UpdateStats> Update(std::vector<Rollout> rollouts);
  // The actors and env streams whose rollouts make the batch.
  static void CountFeeders(const std::vector<Rollout>& rollouts,
                           UpdateStats& stats);
  absl::StatusOr<UpdateStats> Optimise(std::vector<Rollout>& rollouts,
                                       UpdateGuard& guard);
  // Keeps the update or, when its statistics are faulty, rolls it back;
  // either way the counters and the version advance.
  absl::Status Commit(const std::vector<Rollout>& rollouts,
                      const UpdateSums& sums, UpdateGuard& guard,
                      UpdateStats& stats);
  // Absorbs a kept update's observations into the normaliser.
  absl::Status UpdateNormaliser(const std::vector<Rollout>& rollouts);
  // Refits the linear critic to a kept update's value targets (its loss
  // becomes the update's value_loss); a fit that fails keeps the old one
  // and says so.
  void FitLinearCritic(const PreparedBatch& prepared, UpdateStats& stats);
  void AddTotals(const UpdateSums& sums, UpdateStats& stats);

  const LearnerConfig config_;
  std::shared_ptr<ReplicaGroup> replicas_;
  PolicyNetwork policy_;
  ValueNetwork value_;
  RunningMeanStd normalizer_;
  RewardScaler reward_scaler_;
  std::unique_ptr<PolicyUpdater> updater_;
  // Created after the networks, from the same generator, so that a run
  // without it initialises exactly as before it existed.
  std::unique_ptr<Ex2Bonus> exploration_;
  // TRPO's --trpo_linear_baseline: values the states instead of value_.
  std::unique_ptr<LinearCritic> linear_critic_;
  SegmentIntake intake_;
  BatchPreparer preparer_;
  std::mt19937_64 rng_;
  // Totals over the global batch, the same on every replica.
  int64_t version_ = 0;
  int64_t env_steps_ = 0;
  int64_t rejected_ = 0;
  int64_t stale_segments_ = 0;
  int64_t stale_steps_ = 0;
  int64_t episodes_ = 0;
  int64_t rolled_back_updates_ = 0;
};

}  // namespace vantage

#endif  // VANTAGE_LEARNER_LEARNER_CORE_H_
