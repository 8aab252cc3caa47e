#include "learner/learner_core.h"

#include <ATen/ATen.h>
#include <ATen/core/grad_mode.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <mutex>
#include <numeric>
#include <set>
#include <utility>

#include "absl/strings/str_cat.h"
#include "learner/batch/linear_critic.h"
#include "learner/exploration/ex2_bonus.h"
#include "learner/parallel/replica_reductions.h"
#include "learner/update/update_guard.h"

namespace vantage {

namespace {

std::mutex& InitialisationMutex() {
  static std::mutex mutex;
  return mutex;
}

// The exploration bonus, if the run has one, with its own stream, so that
// the minibatches and masks stay those of the learner's generator.
std::unique_ptr<Ex2Bonus> MakeExploration(
    const LearnerConfig& config,
    const std::shared_ptr<ReplicaGroup>& replicas) {
  if (!config.exploration.ex2.has_value()) return nullptr;
  return std::make_unique<Ex2Bonus>(
      *config.exploration.ex2, config.spec,
      ReplicaSeed(config.seed, replicas->rank()) ^ 0x4558324558320000ULL,
      replicas);
}

}  // namespace

absl::StatusOr<std::unique_ptr<LearnerCore>> LearnerCore::Create(
    const LearnerConfig& config, std::shared_ptr<ReplicaGroup> replicas) {
  if (absl::Status status = config.Validate(); !status.ok()) return status;
  if (replicas == nullptr) replicas = SoloReplicaGroup();
  std::unique_ptr<LearnerCore> core = Construct(config, std::move(replicas));
  if (absl::Status status = core->SynchroniseReplicas(); !status.ok()) {
    return status;
  }
  return core;
}

std::unique_ptr<LearnerCore> LearnerCore::Construct(
    const LearnerConfig& config, std::shared_ptr<ReplicaGroup> replicas) {
  // Network initialisation draws from LibTorch's global generator; held,
  // so that learners built at once in one process (replicas in threads)
  // each draw the seed's values rather than an interleaving.
  std::lock_guard<std::mutex> lock(InitialisationMutex());
  at::manual_seed(config.seed);
  return std::unique_ptr<LearnerCore>(
      new LearnerCore(config, std::move(replicas)));
}

LearnerCore::LearnerCore(const LearnerConfig& config,
                         std::shared_ptr<ReplicaGroup> replicas)
    : config_(config),
      replicas_(std::move(replicas)),
      policy_(config.spec, config.network),
      value_(MakeValueNetwork(config.spec, config.network, *policy_)),
      normalizer_(config.spec.observation_size),
      reward_scaler_(config.advantage.gamma, config.reward_clip),
      // Validated by Create, so the algorithm exists.
      updater_(MakePolicyUpdater(config.algorithm, policy_, value_, replicas_)
                   .value()),
      exploration_(MakeExploration(config, replicas_)),
      linear_critic_(config.linear_critic() ? std::make_unique<LinearCritic>(
                                                  config.spec.observation_size)
                                            : nullptr),
      intake_(config),
      preparer_(config_, *value_, normalizer_, reward_scaler_,
                exploration_.get(), *replicas_, linear_critic_.get()),
      rng_(ReplicaSeed(config.seed, replicas_->rank())) {}

LearnerCore::~LearnerCore() = default;

absl::Status LearnerCore::SynchroniseReplicas() {
  if (replicas_->world_size() == 1) return absl::OkStatus();
  at::NoGradGuard no_grad;
  std::vector<at::Tensor> parameters = NetworkParameters(*policy_, *value_);
  if (exploration_ != nullptr) {
    for (const at::Tensor& p : exploration_->parameters()) {
      parameters.push_back(p);
    }
  }
  const int64_t local_version = version_;
  std::vector<at::Tensor> state = {
      at::cat({at::tensor({normalizer_.count(), static_cast<double>(version_),
                           static_cast<double>(env_steps_),
                           static_cast<double>(episodes_),
                           static_cast<double>(rejected_),
                           static_cast<double>(stale_segments_),
                           static_cast<double>(stale_steps_),
                           static_cast<double>(rolled_back_updates_)},
                          at::kDouble),
               normalizer_.mean(), normalizer_.var(),
               linear_critic_ != nullptr ? linear_critic_->coefficients()
                                         : at::zeros({0}, at::kDouble)})};
  try {
    replicas_->Broadcast(parameters, /*root=*/0);
    replicas_->Broadcast(state, /*root=*/0);
  } catch (const std::exception& error) {
    return absl::UnavailableError(
        absl::StrCat("learner replica ", replicas_->rank(),
                     " could not receive rank 0's state: ", error.what()));
  }
  const at::Tensor& s = state[0];
  const int64_t size = normalizer_.size();
  const auto count = [&](int i) {
    return static_cast<int64_t>(s[i].item<double>());
  };
  if (count(1) != local_version) {
    return absl::FailedPreconditionError(absl::StrCat(
        "learner replica ", replicas_->rank(), " is at policy version ",
        local_version, " but rank 0 at ", count(1),
        " (the replicas must resume from the same checkpoint)"));
  }
  env_steps_ = count(2);
  episodes_ = count(3);
  rejected_ = count(4);
  stale_segments_ = count(5);
  stale_steps_ = count(6);
  rolled_back_updates_ = count(7);
  if (linear_critic_ != nullptr) {
    if (absl::Status status =
            linear_critic_->Restore(s.slice(0, 8 + 2 * size).clone());
        !status.ok()) {
      return status;
    }
  }
  return normalizer_.Restore(s[0].item<double>(), s.slice(0, 8, 8 + size),
                             s.slice(0, 8 + size, 8 + 2 * size));
}

PolicyWeights LearnerCore::CurrentWeights() {
  return ExportPolicyWeights(*policy_, normalizer_, version_);
}

double LearnerCore::MeanRecentReturn() const {
  const std::deque<double>& returns = intake_.recent_returns();
  if (returns.empty()) return std::numeric_limits<double>::quiet_NaN();
  return std::accumulate(returns.begin(), returns.end(), 0.0) / returns.size();
}

absl::StatusOr<UpdateStats> LearnerCore::RunUpdate(SegmentSource& source) {
  absl::StatusOr<std::vector<Rollout>> rollouts =
      intake_.NextBatch(source, version_);
  if (!rollouts.ok()) return rollouts.status();
  return Update(*std::move(rollouts));
}

absl::Status LearnerCore::Commit(const std::vector<Rollout>& rollouts,
                                 const UpdateSums& sums, UpdateGuard& guard,
                                 UpdateStats& stats) {
  // The same decision on every replica: the statistics are global and the
  // parameters identical.
  stats.rollback_reason =
      stats.exploration.fault.empty()
          ? guard.Fault(stats.algorithm, config_.rollback_gradient_norm)
          : stats.exploration.fault;
  if (!stats.rollback_reason.empty()) {
    guard.Restore();
    stats.rolled_back = true;
    ++rolled_back_updates_;
    std::fprintf(stderr,
                 "learner: warning: update to version %ld rolled back (%s); "
                 "its batch of %ld steps is dropped\n",
                 static_cast<long>(version_ + 1), stats.rollback_reason.c_str(),
                 static_cast<long>(sums.samples));
  } else {
    if (absl::Status status = UpdateNormaliser(rollouts); !status.ok()) {
      return status;
    }
    if (exploration_ != nullptr) exploration_->Commit();
  }
  AddTotals(sums, stats);
  sums.BatchStatistics(stats);
  return absl::OkStatus();
}

// A dropped batch must not move the statistics either; byte observations
// are not normalised, so have none, nor have a run's that normalises none.
absl::Status LearnerCore::UpdateNormaliser(
    const std::vector<Rollout>& rollouts) {
  if (config_.spec.byte_observations() || !config_.normalize_observations) {
    return absl::OkStatus();
  }
  std::vector<at::Tensor> observations;
  for (const Rollout& rollout : rollouts) {
    observations.push_back(rollout.observations.slice(0, 0, config_.horizon));
  }
  return UpdateAcrossReplicas(*replicas_, normalizer_, at::cat(observations));
}

void LearnerCore::FitLinearCritic(const PreparedBatch& prepared,
                                  UpdateStats& stats) {
  const TrainingBatch& batch = prepared.batch;
  const int64_t rows = batch.observations.size(0) * batch.observations.size(1);
  const at::Tensor features =
      LinearCritic::Features(batch.observations.reshape({rows, -1}),
                             batch.episode_steps.reshape({rows}));
  absl::StatusOr<double> loss =
      linear_critic_->Fit(features, prepared.update.returns, *replicas_);
  if (loss.ok()) {
    stats.algorithm.value_loss = *loss;
    return;
  }
  std::fprintf(stderr,
               "learner: warning: after the update to version %ld: %s\n",
               static_cast<long>(version_),
               std::string(loss.status().message()).c_str());
}

void LearnerCore::AddTotals(const UpdateSums& sums, UpdateStats& stats) {
  env_steps_ += static_cast<int64_t>(sums.samples);
  episodes_ += static_cast<int64_t>(sums.episodes);
  rejected_ += static_cast<int64_t>(sums.rejected);
  stale_segments_ += static_cast<int64_t>(sums.stale_segments);
  stale_steps_ += static_cast<int64_t>(sums.stale_steps);
  intake_.ResetCounts();
  ++version_;
  stats.rolled_back_updates = rolled_back_updates_;
  stats.policy_version = version_;
  stats.env_steps = env_steps_;
  stats.episodes = episodes_;
  stats.rejected_segments = rejected_;
  stats.first_rejection = intake_.TakeFirstRejection();
  stats.stale_segments = stale_segments_;
  stats.stale_steps = stale_steps_;
  stats.evicted_steps = static_cast<int64_t>(sums.evicted_steps);
}

namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

}  // namespace

absl::StatusOr<UpdateStats> LearnerCore::Update(std::vector<Rollout> rollouts) {
  UpdateGuard guard(*policy_, *value_, *updater_,
                    config_.scale_rewards ? &reward_scaler_ : nullptr,
                    exploration_.get());
  ReplicaGroup& replicas = *replicas_;
  // Only rank 0's generator goes into checkpoints (it is the run's): above
  // rank 0 each update draws from a stream fixed by the seed, the rank and
  // the version, so that a resumed run repeats every replica's draws.
  if (replicas.rank() != 0) {
    rng_.seed(ReplicaSeed(config_.seed, replicas.rank()) +
              static_cast<uint64_t>(version_));
  }
  // A collective that fails (a replica gone) throws from inside the
  // algorithm; nothing of the update may stay.
  try {
    return Optimise(rollouts, guard);
  } catch (const std::exception& error) {
    guard.Restore();
    return absl::UnavailableError(absl::StrCat(
        "the update to version ", version_ + 1, " failed",
        replicas.world_size() > 1
            ? absl::StrCat(" on learner replica ", replicas.rank(), " of ",
                           replicas.world_size(),
                           " (another replica is gone or timed out)")
            : "",
        "; the learner is as before it: ", error.what()));
  }
}

void LearnerCore::CountFeeders(const std::vector<Rollout>& rollouts,
                               UpdateStats& stats) {
  std::set<int64_t> actors;
  std::set<std::pair<int64_t, int64_t>> streams;
  for (const Rollout& rollout : rollouts) {
    actors.insert(rollout.actor_id);
    streams.insert({rollout.actor_id, rollout.env_slot});
  }
  stats.batch_actors = static_cast<int64_t>(actors.size());
  stats.batch_env_slots = static_cast<int64_t>(streams.size());
}

absl::StatusOr<UpdateStats> LearnerCore::Optimise(
    std::vector<Rollout>& rollouts, UpdateGuard& guard) {
  const auto update_start = Clock::now();
  absl::StatusOr<PreparedBatch> prepared =
      preparer_.Prepare(rollouts, version_, rng_);
  if (!prepared.ok()) {
    guard.Restore();
    return prepared.status();
  }
  UpdateStats stats;
  stats.exploration = prepared->exploration;
  const auto optimisation_start = Clock::now();
  stats.advantage_seconds = SecondsSince(update_start);
  stats.algorithm = updater_->Update(
      prepared->update,
      static_cast<double>(env_steps_) / config_.total_env_steps, rng_);
  stats.optimisation_seconds = SecondsSince(optimisation_start);
  const UpdateSums sums =
      UpdateSums::Of(*prepared, stats.algorithm, intake_).Over(*replicas_);
  sums.AlgorithmMeans(replicas_->world_size(), stats.algorithm);
  if (absl::Status status = Commit(rollouts, sums, guard, stats);
      !status.ok()) {
    return status;
  }
  if (linear_critic_ != nullptr && !stats.rolled_back) {
    FitLinearCritic(*prepared, stats);
  }
  stats.rollout_policy_lags = std::move(prepared->lags);
  CountFeeders(rollouts, stats);
  stats.update_seconds = SecondsSince(update_start);
  return stats;
}

}  // namespace vantage
