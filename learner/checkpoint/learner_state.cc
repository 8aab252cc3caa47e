#include <ATen/ATen.h>
#include <torch/serialize/archive.h>

#include <sstream>

#include "absl/strings/str_cat.h"
#include "learner/batch/linear_critic.h"
#include "learner/checkpoint/archive_io.h"
#include "learner/exploration/ex2_bonus.h"
#include "learner/learner_core.h"

// The learner's state in a checkpoint archive: LearnerCore's Save and Load.

namespace vantage {

namespace {

// The spec's shape, which a checkpoint must match.
at::Tensor SpecShape(const EnvSpec& spec) {
  return at::tensor({spec.observation_size, spec.action_size,
                     static_cast<int64_t>(spec.discrete)},
                    at::kLong);
}

// A recurrent core as a checkpoint names it: "gru:64".
std::string CoreDescription(const NetworkConfig& network) {
  return absl::StrCat(CoreName(network.core), ":", network.core_size);
}

// Feed-forward networks' checkpoints hold no "core" entry (those written
// before cores existed neither).
absl::Status CheckCore(torch::serialize::InputArchive& archive,
                       const NetworkConfig& network) {
  std::string saved = "none";
  at::Tensor entry;
  if (archive.try_read("core", entry)) {
    absl::StatusOr<std::string> core = ReadBytes(archive, "core");
    if (!core.ok()) return core.status();
    saved = *core;
  }
  const std::string wanted =
      network.recurrent() ? CoreDescription(network) : "none";
  if (saved == wanted) return absl::OkStatus();
  return absl::InvalidArgumentError(
      absl::StrCat("checkpoint's policy has core ", saved,
                   ", but the run config says ", wanted,
                   " (--core, --core_size): a checkpoint's networks are not "
                   "reinitialised to fit"));
}

// Whether `archive` was written for the run `config` describes: its
// environment, algorithm, torso sharing and recurrent core.
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
  return CheckCore(archive, config.network);
}

}  // namespace

void LearnerCore::Save(torch::serialize::OutputArchive& archive) const {
  if (config_.network.recurrent()) {
    WriteBytes(archive, "core", CoreDescription(config_.network));
  }
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
  if (linear_critic_ != nullptr) {
    torch::serialize::OutputArchive critic;
    linear_critic_->Save(critic);
    archive.write("linear_critic", critic);
  }
  WriteRunningMeanStd(archive, "normalizer", normalizer_);
  std::ostringstream rng;
  rng << rng_;
  WriteBytes(archive, "rng", rng.str());
  archive.write("counters", at::tensor({version_, env_steps_, rejected_,
                                        episodes_, stale_segments_,
                                        stale_steps_, rolled_back_updates_},
                                       at::kLong));
  archive.write("recent_returns",
                at::tensor(std::vector<double>(recent_returns().begin(),
                                               recent_returns().end()),
                           at::kDouble));
}

absl::Status LearnerCore::LoadLinearCritic(
    torch::serialize::InputArchive& archive) {
  if (linear_critic_ == nullptr) return absl::OkStatus();
  torch::serialize::InputArchive critic;
  if (absl::Status status = CatchTorchErrors(
          "checkpoint entry 'linear_critic' is missing (a checkpoint of a run "
          "with the value network cannot continue with "
          "--trpo_linear_baseline)",
          [&] { archive.read("linear_critic", critic); });
      !status.ok()) {
    return status;
  }
  return linear_critic_->Load(critic);
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
  if (absl::Status status = LoadLinearCritic(archive); !status.ok()) {
    return status;
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
  std::deque<double> recent;
  for (int64_t i = 0; i < returns.numel(); ++i) {
    recent.push_back(returns[i].item<double>());
  }
  intake_.RestoreRecentReturns(std::move(recent));
  return absl::OkStatus();
}

absl::StatusOr<std::unique_ptr<LearnerCore>> LearnerCore::Load(
    const LearnerConfig& config, torch::serialize::InputArchive& archive,
    std::shared_ptr<ReplicaGroup> replicas) {
  if (absl::Status status = config.Validate(); !status.ok()) return status;
  if (replicas == nullptr) replicas = SoloReplicaGroup();
  // Synchronised after the state is read, not at creation.
  std::unique_ptr<LearnerCore> core = Construct(config, std::move(replicas));
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
