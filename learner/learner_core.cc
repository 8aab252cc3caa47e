#include "learner/learner_core.h"

#include <ATen/ATen.h>
#include <ATen/core/grad_mode.h>

#include <utility>

#include "absl/strings/str_cat.h"
#include "common/advantage/advantage.h"
#include "learner/ingest/training_batch.h"

namespace vantage {

absl::Status LearnerConfig::Validate() const {
  if (spec.observation_size < 1 || spec.action_size < 1) {
    return absl::InvalidArgumentError("learner needs an environment spec");
  }
  if (horizon < 1 || rollouts_per_batch < 1 || total_env_steps < 1) {
    return absl::InvalidArgumentError(
        "learner horizon, rollouts_per_batch and total_env_steps must be "
        ">= 1");
  }
  if (absl::Status status = advantage.Validate(); !status.ok()) return status;
  return ppo.Validate();
}

absl::StatusOr<std::unique_ptr<LearnerCore>> LearnerCore::Create(
    const LearnerConfig& config) {
  if (absl::Status status = config.Validate(); !status.ok()) return status;
  // Network initialisation draws from LibTorch's global generator.
  at::manual_seed(config.seed);
  return std::unique_ptr<LearnerCore>(new LearnerCore(config));
}

LearnerCore::LearnerCore(const LearnerConfig& config)
    : config_(config),
      policy_(config.spec, config.network),
      value_(config.spec.observation_size, config.network),
      normalizer_(config.spec.observation_size),
      ppo_(policy_, value_, config.ppo),
      stitcher_(config.horizon),
      rng_(config.seed) {}

PolicyWeights LearnerCore::CurrentWeights() {
  return ExportPolicyWeights(*policy_, normalizer_, version_);
}

absl::StatusOr<UpdateStats> LearnerCore::RunUpdate(SegmentSource& source) {
  while (static_cast<int64_t>(pending_.size()) < config_.rollouts_per_batch) {
    absl::StatusOr<Segment> segment = source.Receive();
    if (!segment.ok()) return segment.status();
    if (!ValidateSegment(*segment, config_.spec, config_.max_segment_steps)
             .ok()) {
      ++rejected_;
      continue;
    }
    // Returns count only for segments the stitcher accepts (a duplicate
    // must not count twice).
    const std::vector<double> returns = segment->episode_returns;
    if (!stitcher_.Add(std::move(*segment)).ok()) {
      ++rejected_;
      continue;
    }
    for (double r : returns) {
      recent_returns_.push_back(r);
      if (recent_returns_.size() > 100) recent_returns_.pop_front();
    }
    for (Rollout& rollout : stitcher_.TakeReady()) {
      pending_.push_back(std::move(rollout));
    }
  }
  std::vector<Rollout> rollouts(pending_.begin(),
                                pending_.begin() + config_.rollouts_per_batch);
  pending_.erase(pending_.begin(),
                 pending_.begin() + config_.rollouts_per_batch);

  // The batch is normalised with the statistics the acting policy used
  // (shipped with its weights), so that in sync mode the first epoch's
  // ratios start at 1; the statistics absorb the batch after the update.
  const double clip = config_.observation_clip;
  absl::StatusOr<TrainingBatch> batch =
      AssembleBatch(rollouts, [&](const at::Tensor& observations) {
        at::NoGradGuard no_grad;
        return value_->forward(normalizer_.Normalize(observations, clip));
      });
  if (!batch.ok()) return batch.status();
  absl::StatusOr<Advantages> advantages =
      ComputeAdvantages(batch->advantage_inputs, config_.advantage, rng_);
  if (!advantages.ok()) return advantages.status();

  const int64_t samples = config_.horizon * config_.rollouts_per_batch;
  const at::Tensor observations =
      normalizer_.Normalize(batch->observations.reshape({samples, -1}), clip);
  const double progress =
      static_cast<double>(env_steps_) / config_.total_env_steps;
  const double learning_rate =
      config_.ppo.learning_rate * std::max(0.0, 1.0 - progress);
  UpdateStats stats;
  stats.ppo =
      ppo_.Update(observations, batch->actions.reshape({samples, -1}),
                  batch->behaviour_log_probs.reshape({samples}),
                  advantages->mixed.reshape({samples}),
                  advantages->returns.reshape({samples}), learning_rate, rng_);
  for (const Rollout& rollout : rollouts) {
    if (absl::Status status = normalizer_.Update(
            rollout.observations.slice(0, 0, config_.horizon));
        !status.ok()) {
      return status;
    }
  }
  env_steps_ += samples;
  ++version_;
  stats.policy_version = version_;
  stats.env_steps = env_steps_;
  stats.biased_fraction = advantages->mask.to(at::kFloat).mean().item<double>();
  stats.mean_abs_bias =
      (advantages->biased - advantages->gae).abs().mean().item<double>();
  const at::Tensor targets = advantages->returns;
  const at::Tensor residual = targets - batch->advantage_inputs.values;
  stats.explained_variance =
      1.0 - (residual.var() / (targets.var() + 1e-8)).item<double>();
  stats.rejected_segments = rejected_;
  return stats;
}

}  // namespace vantage
