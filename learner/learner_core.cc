#include "learner/learner_core.h"

#include <ATen/ATen.h>
#include <ATen/core/grad_mode.h>
#include <torch/serialize/archive.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <mutex>
#include <numeric>
#include <sstream>
#include <utility>

#include "absl/strings/str_cat.h"
#include "common/advantage/advantage.h"
#include "learner/archive_io.h"
#include "learner/exploration/ex2_bonus.h"
#include "learner/ingest/training_batch.h"
#include "learner/parallel/replica_reductions.h"
#include "learner/update_guard.h"

namespace vantage {

namespace {

std::mutex& InitialisationMutex() {
  static std::mutex mutex;
  return mutex;
}

}  // namespace

absl::StatusOr<std::unique_ptr<LearnerCore>> LearnerCore::Create(
    const LearnerConfig& config, std::shared_ptr<ReplicaGroup> replicas) {
  if (absl::Status status = config.Validate(); !status.ok()) return status;
  if (replicas == nullptr) replicas = SoloReplicaGroup();
  std::unique_ptr<LearnerCore> core;
  {
    // Network initialisation draws from LibTorch's global generator; held,
    // so that learners built at once in one process (replicas in threads)
    // each draw the seed's values rather than an interleaving.
    std::lock_guard<std::mutex> lock(InitialisationMutex());
    at::manual_seed(config.seed);
    core.reset(new LearnerCore(config, std::move(replicas)));
  }
  if (absl::Status status = core->SynchroniseReplicas(); !status.ok()) {
    return status;
  }
  return core;
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
      stitcher_(config.horizon),
      rng_(ReplicaSeed(config.seed, replicas_->rank())) {
  if (config.exploration.ex2.has_value()) {
    // Its own stream, so that the minibatches and masks stay those of the
    // learner's generator.
    exploration_ = std::make_unique<Ex2Bonus>(
        *config.exploration.ex2, config.spec,
        ReplicaSeed(config.seed, replicas_->rank()) ^ 0x4558324558320000ULL,
        replicas_);
  }
}

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
               normalizer_.mean(), normalizer_.var()})};
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
  return normalizer_.Restore(s[0].item<double>(), s.slice(0, 8, 8 + size),
                             s.slice(0, 8 + size, 8 + 2 * size));
}

PolicyWeights LearnerCore::CurrentWeights() {
  return ExportPolicyWeights(*policy_, normalizer_, version_);
}

double LearnerCore::MeanRecentReturn() const {
  if (recent_returns_.empty()) return std::numeric_limits<double>::quiet_NaN();
  return std::accumulate(recent_returns_.begin(), recent_returns_.end(), 0.0) /
         recent_returns_.size();
}

void LearnerCore::NoteRejection(const Segment& segment,
                                const absl::Status& why) {
  if (!first_rejection_.empty()) return;
  first_rejection_ = absl::StrCat("actor ", segment.actor_id, " slot ",
                                  segment.env_slot, ": ", why.message());
}

absl::StatusOr<UpdateStats> LearnerCore::RunUpdate(SegmentSource& source) {
  // In sync mode (lag 0) only the current version's steps train.
  const int64_t min_version = config_.max_policy_lag < 0
                                  ? std::numeric_limits<int64_t>::min()
                                  : version_ - config_.max_policy_lag;
  unreported_.stale_steps += stitcher_.DropStepsOlderThan(min_version);
  std::vector<Rollout> fresh;
  for (Rollout& rollout : pending_) {
    if (rollout.policy_versions.min().item<int64_t>() >= min_version) {
      fresh.push_back(std::move(rollout));
    } else {
      unreported_.stale_steps += rollout.policy_versions.size(0);
    }
  }
  pending_ = std::move(fresh);
  while (static_cast<int64_t>(pending_.size()) < config_.rollouts_per_batch) {
    absl::StatusOr<Segment> segment = source.Receive();
    if (!segment.ok()) return segment.status();
    absl::Status valid =
        ValidateSegment(*segment, config_.spec, config_.max_segment_steps,
                        config_.value_limits);
    if (valid.ok() && segment->policy_version > version_) {
      valid = absl::FailedPreconditionError(
          absl::StrCat("policy version ", segment->policy_version,
                       " is not published yet (newest ", version_, ")"));
    }
    if (!valid.ok()) {
      ++unreported_.rejected;
      NoteRejection(*segment, valid);
      continue;
    }
    if (segment->policy_version < min_version) {
      ++unreported_.rejected;
      ++unreported_.stale_segments;
      unreported_.stale_steps += segment->steps();
      continue;
    }
    // Returns count only for segments the stitcher accepts (a duplicate
    // must not count twice).
    const std::vector<double> returns = segment->episode_returns;
    // Room for this segment within the budget, at the expense of the
    // streams fed least recently (an abandoned or hostile one first).
    const int64_t budget =
        config_.max_buffered_steps > 0
            ? config_.max_buffered_steps
            : 8 * config_.horizon * config_.rollouts_per_batch;
    stitcher_.EvictDownTo(std::max<int64_t>(0, budget - segment->steps()),
                          segment->actor_id, segment->env_slot);
    const int64_t actor_id = segment->actor_id;
    const int64_t env_slot = segment->env_slot;
    if (absl::Status added = stitcher_.Add(std::move(*segment)); !added.ok()) {
      ++unreported_.rejected;
      if (first_rejection_.empty()) {
        first_rejection_ = absl::StrCat("actor ", actor_id, " slot ", env_slot,
                                        ": ", added.message());
      }
      continue;
    }
    for (double r : returns) {
      recent_returns_.push_back(r);
      if (recent_returns_.size() > 100) recent_returns_.pop_front();
    }
    unreported_.episodes += static_cast<int64_t>(returns.size());
    for (Rollout& rollout : stitcher_.TakeReady()) {
      pending_.push_back(std::move(rollout));
    }
  }
  std::vector<Rollout> rollouts(
      std::make_move_iterator(pending_.begin()),
      std::make_move_iterator(pending_.begin() + config_.rollouts_per_batch));
  pending_.erase(pending_.begin(),
                 pending_.begin() + config_.rollouts_per_batch);
  return Update(std::move(rollouts));
}

// What an update's optimisation works on: the batch, its advantages, the
// algorithm's view of both, and how stale each rollout was.
struct LearnerCore::PreparedBatch {
  ExplorationStats exploration;
  TrainingBatch batch;
  Advantages advantages;
  UpdateBatch update;
  // How many versions behind the current one each rollout's oldest step
  // was acted.
  std::vector<int64_t> lags;
};

// Everything the update's statistics need, summed over the replicas in one
// collective; the algorithm's statistics are means over them.
struct LearnerCore::ReplicaSums {
  double samples = 0, episodes = 0, rejected = 0, stale_segments = 0,
         stale_steps = 0, evicted_steps = 0;
  double return_sum = 0, return_count = 0;  // of the last-100 windows
  double biased_samples = 0, abs_bias_sum = 0;
  // Of the value targets and of their residuals to the critic's values.
  double target_sum = 0, target_squares = 0, residual_sum = 0,
         residual_squares = 0;
  double policy_loss = 0, value_loss = 0, entropy = 0, approx_kl = 0,
         clip_fraction = 0;

  static constexpr double ReplicaSums::*kFields[] = {
      &ReplicaSums::samples,        &ReplicaSums::episodes,
      &ReplicaSums::rejected,       &ReplicaSums::stale_segments,
      &ReplicaSums::stale_steps,    &ReplicaSums::evicted_steps,
      &ReplicaSums::return_sum,     &ReplicaSums::return_count,
      &ReplicaSums::biased_samples, &ReplicaSums::abs_bias_sum,
      &ReplicaSums::target_sum,     &ReplicaSums::target_squares,
      &ReplicaSums::residual_sum,   &ReplicaSums::residual_squares,
      &ReplicaSums::policy_loss,    &ReplicaSums::value_loss,
      &ReplicaSums::entropy,        &ReplicaSums::approx_kl,
      &ReplicaSums::clip_fraction};

  ReplicaSums Over(ReplicaGroup& replicas) const {
    std::vector<double> values;
    for (double ReplicaSums::*field : kFields) values.push_back(this->*field);
    values = SumAcrossReplicas(replicas, values);
    ReplicaSums sums;
    for (size_t i = 0; i < values.size(); ++i) sums.*kFields[i] = values[i];
    return sums;
  }
};

absl::StatusOr<LearnerCore::PreparedBatch> LearnerCore::PrepareBatch(
    std::vector<Rollout>& rollouts) {
  // The batch is normalised with the statistics the acting policy used
  // (shipped with its weights), so that in sync mode the first epoch's
  // ratios start at 1; the statistics absorb the batch after the update.
  const double clip = config_.observation_clip;
  PreparedBatch prepared;
  if (exploration_ != nullptr) {
    prepared.exploration = exploration_->ShapeRewards(rollouts);
  }
  absl::StatusOr<TrainingBatch> batch =
      AssembleBatch(rollouts, [&](const at::Tensor& observations) {
        at::NoGradGuard no_grad;
        return value_->forward(ObservationsForNetwork(config_.spec, normalizer_,
                                                      observations, clip));
      });
  if (!batch.ok()) return batch.status();
  prepared.batch = *std::move(batch);
  AdvantageInputs& inputs = prepared.batch.advantage_inputs;
  if (config_.scale_rewards) {
    if (absl::Status status = reward_scaler_.Observe(rollouts, *replicas_);
        !status.ok()) {
      return status;
    }
    inputs.rewards = reward_scaler_.Scale(inputs.rewards);
  }
  absl::StatusOr<Advantages> advantages =
      ComputeAdvantages(inputs, config_.advantage, rng_);
  if (!advantages.ok()) return advantages.status();
  prepared.advantages = *std::move(advantages);
  prepared.update = MakeUpdateBatch(
      prepared.batch, prepared.advantages, [&](const at::Tensor& raw) {
        return ObservationsForNetwork(config_.spec, normalizer_, raw, clip);
      });
  for (const Rollout& rollout : rollouts) {
    prepared.lags.push_back(version_ -
                            rollout.policy_versions.min().item<int64_t>());
  }
  prepared.update.lagged =
      std::any_of(prepared.lags.begin(), prepared.lags.end(),
                  [](int64_t lag) { return lag > 0; });
  return prepared;
}

LearnerCore::ReplicaSums LearnerCore::SumOverReplicas(
    const PreparedBatch& prepared, AlgorithmStats& algorithm) {
  const Advantages& advantages = prepared.advantages;
  const at::Tensor targets = advantages.returns.to(at::kDouble);
  const at::Tensor residual =
      targets - prepared.batch.advantage_inputs.values.to(at::kDouble);
  ReplicaSums own;
  own.samples =
      static_cast<double>(prepared.update.horizon * prepared.update.streams);
  own.episodes = static_cast<double>(unreported_.episodes);
  own.rejected = static_cast<double>(unreported_.rejected);
  own.stale_segments = static_cast<double>(unreported_.stale_segments);
  own.stale_steps = static_cast<double>(unreported_.stale_steps);
  own.evicted_steps = static_cast<double>(stitcher_.stats().evicted_steps);
  own.return_sum =
      std::accumulate(recent_returns_.begin(), recent_returns_.end(), 0.0);
  own.return_count = static_cast<double>(recent_returns_.size());
  own.biased_samples = advantages.mask.to(at::kDouble).sum().item<double>();
  own.abs_bias_sum = (advantages.biased - advantages.gae)
                         .abs()
                         .to(at::kDouble)
                         .sum()
                         .item<double>();
  own.target_sum = targets.sum().item<double>();
  own.target_squares = targets.pow(2).sum().item<double>();
  own.residual_sum = residual.sum().item<double>();
  own.residual_squares = residual.pow(2).sum().item<double>();
  own.policy_loss = algorithm.policy_loss;
  own.value_loss = algorithm.value_loss;
  own.entropy = algorithm.entropy;
  own.approx_kl = algorithm.approx_kl;
  own.clip_fraction = algorithm.clip_fraction;
  const ReplicaSums sums = own.Over(*replicas_);
  const double world = replicas_->world_size();
  algorithm.policy_loss = sums.policy_loss / world;
  algorithm.value_loss = sums.value_loss / world;
  algorithm.entropy = sums.entropy / world;
  algorithm.approx_kl = sums.approx_kl / world;
  algorithm.clip_fraction = sums.clip_fraction / world;
  return sums;
}

absl::Status LearnerCore::Commit(const std::vector<Rollout>& rollouts,
                                 const ReplicaSums& sums, UpdateGuard& guard,
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
    // A dropped batch must not move the statistics either; byte
    // observations are not normalised, so have none.
    if (!config_.spec.byte_observations()) {
      std::vector<at::Tensor> observations;
      for (const Rollout& rollout : rollouts) {
        observations.push_back(
            rollout.observations.slice(0, 0, config_.horizon));
      }
      if (absl::Status status = UpdateAcrossReplicas(*replicas_, normalizer_,
                                                     at::cat(observations));
          !status.ok()) {
        return status;
      }
    }
    if (exploration_ != nullptr) exploration_->Commit();
  }
  env_steps_ += static_cast<int64_t>(sums.samples);
  episodes_ += static_cast<int64_t>(sums.episodes);
  rejected_ += static_cast<int64_t>(sums.rejected);
  stale_segments_ += static_cast<int64_t>(sums.stale_segments);
  stale_steps_ += static_cast<int64_t>(sums.stale_steps);
  unreported_ = LocalCounts();
  ++version_;
  stats.rolled_back_updates = rolled_back_updates_;
  stats.policy_version = version_;
  stats.env_steps = env_steps_;
  stats.episodes = episodes_;
  stats.mean_return = sums.return_count > 0
                          ? sums.return_sum / sums.return_count
                          : std::numeric_limits<double>::quiet_NaN();
  stats.biased_fraction = sums.biased_samples / sums.samples;
  stats.mean_abs_bias = sums.abs_bias_sum / sums.samples;
  const auto variance = [&](double sum, double squares) {
    return (squares - sum * sum / sums.samples) /
           std::max(sums.samples - 1.0, 1.0);
  };
  stats.explained_variance =
      1.0 - variance(sums.residual_sum, sums.residual_squares) /
                (variance(sums.target_sum, sums.target_squares) + 1e-8);
  stats.rejected_segments = rejected_;
  stats.first_rejection = std::move(first_rejection_);
  first_rejection_.clear();
  stats.stale_segments = stale_segments_;
  stats.stale_steps = stale_steps_;
  stats.evicted_steps = static_cast<int64_t>(sums.evicted_steps);
  return absl::OkStatus();
}

absl::StatusOr<UpdateStats> LearnerCore::Update(std::vector<Rollout> rollouts) {
  using Clock = std::chrono::steady_clock;
  const auto seconds_since = [](Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
  };
  const auto update_start = Clock::now();
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
    absl::StatusOr<PreparedBatch> prepared = PrepareBatch(rollouts);
    if (!prepared.ok()) {
      guard.Restore();
      return prepared.status();
    }
    UpdateStats stats;
    stats.exploration = prepared->exploration;
    const auto optimisation_start = Clock::now();
    stats.advantage_seconds = seconds_since(update_start);
    stats.algorithm = updater_->Update(
        prepared->update,
        static_cast<double>(env_steps_) / config_.total_env_steps, rng_);
    stats.optimisation_seconds = seconds_since(optimisation_start);
    const ReplicaSums sums = SumOverReplicas(*prepared, stats.algorithm);
    if (absl::Status status = Commit(rollouts, sums, guard, stats);
        !status.ok()) {
      return status;
    }
    stats.rollout_policy_lags = std::move(prepared->lags);
    stats.update_seconds = seconds_since(update_start);
    return stats;
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

namespace {

// The spec's shape, which a checkpoint must match.
at::Tensor SpecShape(const EnvSpec& spec) {
  return at::tensor({spec.observation_size, spec.action_size,
                     static_cast<int64_t>(spec.discrete)},
                    at::kLong);
}

// Whether `archive` was written for the run `config` describes: its
// environment, algorithm and torso sharing.
absl::Status CheckCheckpointFits(const LearnerConfig& config,
                                 torch::serialize::InputArchive& archive) {
  absl::StatusOr<std::string> name = ReadBytes(archive, "spec.name");
  if (!name.ok()) return name.status();
  at::Tensor shape;
  if (absl::Status status = ReadTensor(archive, "spec.shape", shape);
      !status.ok()) {
    return status;
  }
  if (*name != config.spec.name || !shape.equal(SpecShape(config.spec))) {
    return absl::InvalidArgumentError(absl::StrCat(
        "checkpoint is for environment '", *name,
        "' with a different spec "
        "than the configured '",
        config.spec.name, "' (observation ", config.spec.observation_size,
        ", action ", config.spec.ActionString(), ")"));
  }
  absl::StatusOr<std::string> algorithm = ReadBytes(archive, "algorithm");
  if (!algorithm.ok()) return algorithm.status();
  if (*algorithm != config.algorithm.name) {
    return absl::InvalidArgumentError(
        absl::StrCat("checkpoint was trained with ", *algorithm, ", not ",
                     config.algorithm.name));
  }
  // Checkpoints written before torsos could be shared hold no entry.
  at::Tensor shared_entry;
  bool shared_torso = false;
  if (archive.try_read("shared_torso", shared_entry)) {
    if (shared_entry.scalar_type() != at::kLong || shared_entry.numel() != 1 ||
        shared_entry.item<int64_t>() < 0 || shared_entry.item<int64_t>() > 1) {
      return absl::InvalidArgumentError(
          "checkpoint entry 'shared_torso' is not one 0 or 1");
    }
    shared_torso = shared_entry.item<int64_t>() == 1;
  }
  if (shared_torso != config.network.shared_torso) {
    return absl::InvalidArgumentError(absl::StrCat(
        "checkpoint's networks ", shared_torso ? "share" : "do not share",
        " their torso, but the run config says the opposite "
        "(--shared_torso)"));
  }
  return absl::OkStatus();
}

}  // namespace

void LearnerCore::Save(torch::serialize::OutputArchive& archive) const {
  WriteBytes(archive, "spec.name", config_.spec.name);
  archive.write("spec.shape", SpecShape(config_.spec));
  WriteBytes(archive, "algorithm", config_.algorithm.name);
  WriteModule(archive, "policy", *policy_);
  // A shared torso is written with both networks; this says the copies are
  // one.
  archive.write("shared_torso",
                at::tensor(int64_t{config_.network.shared_torso ? 1 : 0}));
  WriteModule(archive, "value", *value_);
  torch::serialize::OutputArchive updater, scaler;
  updater_->Save(updater);
  reward_scaler_.Save(scaler);
  archive.write("updater", updater);
  archive.write("reward_scaler", scaler);
  if (exploration_ != nullptr) exploration_->Save(archive, "ex2");
  WriteRunningMeanStd(archive, "normalizer", normalizer_);
  std::ostringstream rng;
  rng << rng_;
  WriteBytes(archive, "rng", rng.str());
  archive.write("counters", at::tensor({version_, env_steps_, rejected_,
                                        episodes_, stale_segments_,
                                        stale_steps_, rolled_back_updates_},
                                       at::kLong));
  archive.write("recent_returns",
                at::tensor(std::vector<double>(recent_returns_.begin(),
                                               recent_returns_.end()),
                           at::kDouble));
}

absl::Status LearnerCore::LoadModels(torch::serialize::InputArchive& archive) {
  torch::serialize::InputArchive updater, scaler;
  if (absl::Status status = CatchTorchErrors(
          "checkpoint entries 'updater' or 'reward_scaler' are missing",
          [&] {
            archive.read("updater", updater);
            archive.read("reward_scaler", scaler);
          });
      !status.ok()) {
    return status;
  }
  for (absl::Status status :
       {ReadModule(archive, "policy", *policy_),
        ReadModule(archive, "value", *value_), updater_->Load(updater),
        reward_scaler_.Load(scaler),
        ReadRunningMeanStd(archive, "normalizer", normalizer_)}) {
    if (!status.ok()) return status;
  }
  if (exploration_ == nullptr) return absl::OkStatus();
  if (absl::Status status = exploration_->Load(archive, "ex2"); !status.ok()) {
    return absl::InvalidArgumentError(
        absl::StrCat(status.message(),
                     " (the run's EX2 state; a checkpoint of a run "
                     "without EX2 cannot continue with it)"));
  }
  return absl::OkStatus();
}

absl::Status LearnerCore::LoadCounters(
    torch::serialize::InputArchive& archive) {
  absl::StatusOr<std::string> rng = ReadBytes(archive, "rng");
  if (!rng.ok()) return rng.status();
  std::istringstream rng_text(*rng);
  rng_text >> rng_;
  if (rng_text.fail()) {
    return absl::InvalidArgumentError("checkpoint entry 'rng' is malformed");
  }
  at::Tensor counters, returns;
  for (absl::Status status : {ReadTensor(archive, "counters", counters),
                              ReadTensor(archive, "recent_returns", returns)}) {
    if (!status.ok()) return status;
  }
  // Checkpoints written before rollbacks existed hold 6 counters.
  if (counters.scalar_type() != at::kLong || counters.dim() != 1 ||
      (counters.numel() != 6 && counters.numel() != 7) ||
      returns.scalar_type() != at::kDouble || returns.dim() != 1 ||
      returns.numel() > 100) {
    return absl::InvalidArgumentError(
        "checkpoint entries 'counters' or 'recent_returns' are malformed");
  }
  version_ = counters[0].item<int64_t>();
  env_steps_ = counters[1].item<int64_t>();
  rejected_ = counters[2].item<int64_t>();
  episodes_ = counters[3].item<int64_t>();
  stale_segments_ = counters[4].item<int64_t>();
  stale_steps_ = counters[5].item<int64_t>();
  if (counters.numel() == 7) rolled_back_updates_ = counters[6].item<int64_t>();
  for (int64_t i = 0; i < returns.numel(); ++i) {
    recent_returns_.push_back(returns[i].item<double>());
  }
  return absl::OkStatus();
}

absl::StatusOr<std::unique_ptr<LearnerCore>> LearnerCore::Load(
    const LearnerConfig& config, torch::serialize::InputArchive& archive,
    std::shared_ptr<ReplicaGroup> replicas) {
  if (absl::Status status = config.Validate(); !status.ok()) return status;
  if (replicas == nullptr) replicas = SoloReplicaGroup();
  // Synchronised after the state is read, not at creation.
  std::unique_ptr<LearnerCore> core;
  {
    std::lock_guard<std::mutex> lock(InitialisationMutex());
    at::manual_seed(config.seed);
    core.reset(new LearnerCore(config, replicas));
  }
  if (absl::Status status = CheckCheckpointFits(config, archive);
      !status.ok()) {
    return status;
  }
  if (absl::Status status = core->LoadModels(archive); !status.ok()) {
    return status;
  }
  if (absl::Status status = core->LoadCounters(archive); !status.ok()) {
    return status;
  }
  if (absl::Status status = core->SynchroniseReplicas(); !status.ok()) {
    return status;
  }
  return core;
}

}  // namespace vantage
