#include "actor/actor_core.h"

#include <ATen/ATen.h>
#include <ATen/CPUGeneratorImpl.h>
#include <ATen/core/grad_mode.h>

#include <utility>

#include "absl/strings/str_cat.h"

namespace vantage {

absl::Status ActorConfig::Validate() const {
  if (env.empty()) return absl::InvalidArgumentError("actor needs an env");
  if (num_envs < 1) {
    return absl::InvalidArgumentError(
        absl::StrCat("actor needs num_envs >= 1, got ", num_envs));
  }
  if (segment_length < 1) {
    return absl::InvalidArgumentError(
        absl::StrCat("actor needs segment_length >= 1, got ", segment_length));
  }
  if (!(observation_clip > 0)) {
    return absl::InvalidArgumentError("observation_clip must be > 0");
  }
  return absl::OkStatus();
}

absl::StatusOr<std::unique_ptr<ActorCore>> ActorCore::Create(
    const ActorConfig& config) {
  if (absl::Status status = config.Validate(); !status.ok()) return status;
  absl::StatusOr<std::unique_ptr<VectorEnv>> envs =
      VectorEnv::Create(config.env, config.num_envs, config.seed);
  if (!envs.ok()) return envs.status();
  if (absl::Status status = (*envs)->Reset(); !status.ok()) return status;
  return std::unique_ptr<ActorCore>(new ActorCore(config, std::move(*envs)));
}

ActorCore::ActorCore(const ActorConfig& config, std::unique_ptr<VectorEnv> envs)
    : config_(config),
      envs_(std::move(envs)),
      policy_(envs_->spec(), config.network),
      normalizer_(envs_->spec().observation_size),
      // Action sampling is seeded apart from the environments' resets.
      generator_(at::make_generator<at::CPUGeneratorImpl>(
          config.seed * 0x9E3779B97F4A7C15ULL + config.actor_id + 1)),
      next_sequence_(config.num_envs, 0) {}

absl::Status ActorCore::SetWeights(const PolicyWeights& weights) {
  if (absl::Status status = ImportPolicyWeights(weights, *policy_, normalizer_);
      !status.ok()) {
    return status;
  }
  version_ = weights.version;
  has_weights_ = true;
  return absl::OkStatus();
}

at::Tensor ActorCore::CurrentObservations() const {
  const absl::Span<const double> observations = envs_->observations();
  return at::from_blob(const_cast<double*>(observations.data()),
                       {envs_->size(), spec().observation_size}, at::kDouble)
      .to(at::kFloat);
}

absl::Status ActorCore::CollectSegments(SegmentSink& sink) {
  if (!has_weights_) {
    return absl::FailedPreconditionError(
        "the actor has no policy weights yet; SetWeights first");
  }
  const int64_t m = envs_->size();
  const int64_t steps = config_.segment_length;
  const int64_t obs = spec().observation_size;
  const int64_t act = spec().discrete ? 1 : spec().action_size;
  at::Tensor observations = at::empty({steps + 1, m, obs}, at::kFloat);
  at::Tensor actions = at::empty({steps, m, act}, at::kFloat);
  at::Tensor log_probs = at::empty({steps, m}, at::kFloat);
  at::Tensor rewards = at::empty({steps, m}, at::kFloat);
  at::Tensor terminated = at::empty({steps, m}, at::kBool);
  at::Tensor truncated = at::empty({steps, m}, at::kBool);
  std::vector<std::vector<at::Tensor>> finals(m);
  std::vector<Segment> segments(m);

  at::NoGradGuard no_grad;
  observations[0].copy_(CurrentObservations());
  for (int64_t t = 0; t < steps; ++t) {
    const at::Tensor output = policy_->forward(
        normalizer_.Normalize(observations[t], config_.observation_clip));
    const at::Tensor action = policy_->Act(output, false, generator_);
    actions[t].copy_(action);
    log_probs[t].copy_(policy_->LogProb(output, action));
    const at::Tensor as_double = action.to(at::kDouble).contiguous();
    actions_.assign(as_double.data_ptr<double>(),
                    as_double.data_ptr<double>() + as_double.numel());
    if (absl::Status status = envs_->Step(actions_); !status.ok()) {
      return status;
    }
    // Plain stores: a tensor op per element would cost more than a step.
    float* reward_row = rewards.data_ptr<float>() + t * m;
    bool* terminated_row = terminated.data_ptr<bool>() + t * m;
    bool* truncated_row = truncated.data_ptr<bool>() + t * m;
    for (int64_t i = 0; i < m; ++i) {
      reward_row[i] = static_cast<float>(envs_->rewards()[i]);
      terminated_row[i] = envs_->terminated()[i] != 0;
      truncated_row[i] = envs_->truncated()[i] != 0;
    }
    for (const FinishedEpisode& episode : envs_->finished()) {
      Segment& segment = segments[episode.env_index];
      segment.episode_returns.push_back(episode.episode_return);
      segment.episode_lengths.push_back(episode.length);
      if (episode.truncated) {
        finals[episode.env_index].push_back(
            at::from_blob(
                const_cast<double*>(envs_->final_observations().data() +
                                    episode.env_index * obs),
                {obs}, at::kDouble)
                .to(at::kFloat));
      }
    }
    observations[t + 1].copy_(CurrentObservations());
  }
  env_steps_ += m * steps;

  for (int64_t i = 0; i < m; ++i) {
    Segment& segment = segments[i];
    segment.actor_id = config_.actor_id;
    segment.env_slot = i;
    segment.sequence = next_sequence_[i]++;
    segment.policy_version = version_;
    segment.observations = observations.select(1, i).clone();
    segment.actions = actions.select(1, i).clone();
    segment.behaviour_log_probs = log_probs.select(1, i).clone();
    segment.rewards = rewards.select(1, i).clone();
    segment.terminated = terminated.select(1, i).clone();
    segment.truncated = truncated.select(1, i).clone();
    segment.final_observations = finals[i].empty()
                                     ? at::empty({0, obs}, at::kFloat)
                                     : at::stack(finals[i]);
    if (absl::Status status = sink.Send(std::move(segment)); !status.ok()) {
      return status;
    }
  }
  return absl::OkStatus();
}

}  // namespace vantage
