#include "actor/actor_core.h"

#include <ATen/ATen.h>
#include <ATen/CPUGeneratorImpl.h>
#include <ATen/core/grad_mode.h>
#include <c10/util/Exception.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/types/span.h"
#include "common/nn/distributions.h"
#include "common/util/state_bytes.h"

namespace vantage {
namespace {

constexpr char kStateKind[] = "actor_core";
constexpr uint32_t kStateVersion = 1;

// The generator's own serialisation (mt19937 state and the cached normal
// samples), as bytes.
std::string GeneratorState(at::Generator generator) {
  std::lock_guard<std::mutex> lock(generator.mutex());
  const at::Tensor state = generator.get_state().contiguous();
  return std::string(reinterpret_cast<const char*>(state.data_ptr<uint8_t>()),
                     state.numel());
}

// The environments' observations (doubles) into `row` [m, obs] of a
// segment's observations, in its dtype (float32, or uint8 for byte
// observations, whose values are integers in range): plain stores, as
// ObservationTensor converts.
void StoreObservations(absl::Span<const double> values, at::Tensor row) {
  if (row.scalar_type() == at::kByte) {
    uint8_t* out = row.data_ptr<uint8_t>();
    for (size_t i = 0; i < values.size(); ++i) {
      out[i] = static_cast<uint8_t>(values[i]);
    }
  } else {
    float* out = row.data_ptr<float>();
    for (size_t i = 0; i < values.size(); ++i) {
      out[i] = static_cast<float>(values[i]);
    }
  }
}

// Masks of one byte per action, [rows, actions], as a bool tensor view.
at::Tensor MaskTensor(const std::vector<uint8_t>& masks, int64_t rows) {
  return at::from_blob(const_cast<uint8_t*>(masks.data()),
                       {rows, static_cast<int64_t>(masks.size()) / rows},
                       at::kBool);
}

// A recurrent policy's `count` state floats (none for a feed-forward one,
// whose states hold none), all finite.
std::vector<double> ReadCoreStates(StateReader& reader, size_t count) {
  if (count == 0) return {};
  std::vector<double> states =
      reader.GetDoubles("the recurrent policy's states", count);
  reader.Check(std::all_of(states.begin(), states.end(),
                           [](double v) { return std::isfinite(v); }),
               "a non-finite recurrent state");
  return states;
}

}  // namespace

absl::StatusOr<std::unique_ptr<ActorCore>> ActorCore::Create(
    const ActorConfig& config) {
  if (absl::Status status = config.Validate(); !status.ok()) return status;
  absl::StatusOr<std::unique_ptr<VectorEnv>> envs = VectorEnv::Create(
      config.env, config.num_envs, config.seed, config.env_options);
  if (!envs.ok()) return envs.status();
  if (absl::Status status = CheckNetworkConfig(config.network, (*envs)->spec());
      !status.ok()) {
    return status;
  }
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
      stream_actor_id_(config.actor_id),
      next_sequence_(config.num_envs, 0),
      core_states_(config.num_envs * config.network.core_state_size(), 0.0f) {}

absl::Status ActorCore::SetWeights(const PolicyWeights& weights) {
  if (absl::Status status = ImportPolicyWeights(weights, *policy_, normalizer_);
      !status.ok()) {
    return status;
  }
  version_ = weights.version;
  has_weights_ = true;
  absl::StatusOr<MlpPolicyKernel> kernel = MlpPolicyKernel::Create(
      spec(), *policy_, normalizer_, config_.observation_clip);
  if (kernel.ok()) {
    kernel_ = std::move(*kernel);
  } else {
    kernel_.reset();
    if (!told_libtorch_) {
      std::fprintf(stderr, "actor %ld (%s): acting on LibTorch: %s\n",
                   static_cast<long>(config_.actor_id), config_.env.c_str(),
                   std::string(kernel.status().message()).c_str());
      told_libtorch_ = true;
    }
  }
  return absl::OkStatus();
}

void ActorCore::Act(const at::Tensor& observations_row, float* actions,
                    float* log_probs) {
  const int64_t m = envs_->size();
  const int64_t width = spec().action_width();
  if (kernel_) {
    kernel_outputs_.resize(m * kernel_->output_size());
    kernel_->Forward(envs_->observations().data(), m, kernel_outputs_.data(),
                     core_states_.data());
    if (!envs_->action_masks().empty()) {
      MaskLogitsInPlace(kernel_outputs_.data(), envs_->action_masks().data(), m,
                        kernel_->output_size());
    }
    kernel_->Act(kernel_outputs_.data(), m, generator_, actions, log_probs);
  } else {
    const at::Tensor inputs = ObservationsForNetwork(
        spec(), normalizer_, observations_row, config_.observation_clip);
    at::Tensor output;
    if (policy_->recurrent()) {
      // The states stay in core_states_: LibTorch writes its next ones there.
      at::Tensor states =
          at::from_blob(core_states_.data(),
                        {m, static_cast<int64_t>(core_states_.size()) / m});
      output = policy_->Step(inputs, states);
      std::copy_n(states.contiguous().data_ptr<float>(), core_states_.size(),
                  core_states_.data());
    } else {
      output = policy_->forward(inputs);
    }
    if (!envs_->action_masks().empty()) {
      output = MaskLogits(output, MaskTensor(envs_->action_masks(), m));
    }
    const at::Tensor action = policy_->Act(output, false, generator_);
    const at::Tensor log_prob = policy_->LogProb(output, action);
    std::copy_n(action.contiguous().data_ptr<float>(), m * width, actions);
    std::copy_n(log_prob.contiguous().data_ptr<float>(), m, log_probs);
  }
  actions_.assign(actions, actions + m * width);
}

// One CollectSegments call's buffers, time-major ([steps(+1), m, ...]),
// and what each slot's segment gathers besides.
struct ActorCore::Rollout {
  Rollout(int64_t steps, int64_t m, int64_t obs, int64_t act,
          at::ScalarType observation_dtype)
      : steps(steps),
        m(m),
        obs(obs),
        act(act),
        observation_dtype(observation_dtype),
        observations(at::empty({steps + 1, m, obs}, observation_dtype)),
        actions(at::empty({steps, m, act}, at::kFloat)),
        log_probs(at::empty({steps, m}, at::kFloat)),
        rewards(at::empty({steps, m}, at::kFloat)),
        terminated(at::empty({steps, m}, at::kBool)),
        truncated(at::empty({steps, m}, at::kBool)),
        finals(m),
        segments(m) {}

  const int64_t steps;
  const int64_t m;
  const int64_t obs;
  const int64_t act;
  const at::ScalarType observation_dtype;
  at::Tensor observations;
  at::Tensor actions;
  at::Tensor log_probs;
  at::Tensor rewards;
  at::Tensor terminated;
  at::Tensor truncated;
  // Per slot: the observations its truncated episodes ended on.
  std::vector<std::vector<at::Tensor>> finals;
  // A recurrent policy's state before step 0 [m, state size].
  at::Tensor core_states;
  // Masked actions: each step's legal actions [steps, m, actions].
  at::Tensor action_masks;
  std::vector<Segment> segments;
};

absl::Status ActorCore::CollectSegments(SegmentSink& sink) {
  if (!has_weights_) {
    return absl::FailedPreconditionError(
        "the actor has no policy weights yet; SetWeights first");
  }
  Rollout rollout(config_.segment_length, envs_->size(),
                  spec().observation_size, spec().action_width(),
                  spec().byte_observations() ? at::kByte : at::kFloat);

  at::NoGradGuard no_grad;
  StoreObservations(envs_->observations(), rollout.observations[0]);
  for (int64_t i = 0; i < rollout.m; ++i) {
    rollout.segments[i].first_episode_step = envs_->episode_lengths()[i];
  }
  if (!core_states_.empty()) {
    rollout.core_states =
        at::from_blob(
            core_states_.data(),
            {rollout.m, static_cast<int64_t>(core_states_.size()) / rollout.m})
            .clone();
  }
  if (spec().action_masks) {
    rollout.action_masks =
        at::empty({rollout.steps, rollout.m, spec().action_size}, at::kBool);
  }
  for (int64_t t = 0; t < rollout.steps; ++t) {
    if (absl::Status status = CollectStep(t, rollout); !status.ok()) {
      return status;
    }
  }
  env_steps_ += rollout.m * rollout.steps;
  return SendSegments(rollout, sink);
}

absl::Status ActorCore::CollectStep(int64_t t, Rollout& rollout) {
  const int64_t m = rollout.m;
  const auto inference_start = std::chrono::steady_clock::now();
  if (rollout.action_masks.defined()) {
    const std::vector<uint8_t>& masks = envs_->action_masks();
    std::memcpy(rollout.action_masks[t].data_ptr<bool>(), masks.data(),
                masks.size());
  }
  Act(rollout.observations[t],
      rollout.actions.data_ptr<float>() + t * m * rollout.act,
      rollout.log_probs.data_ptr<float>() + t * m);
  const auto env_start = std::chrono::steady_clock::now();
  if (absl::Status status = envs_->Step(actions_); !status.ok()) {
    return status;
  }
  const auto env_end = std::chrono::steady_clock::now();
  inference_seconds_ +=
      std::chrono::duration<double>(env_start - inference_start).count();
  env_seconds_ += std::chrono::duration<double>(env_end - env_start).count();
  RecordStep(t, rollout);
  return absl::OkStatus();
}

void ActorCore::RecordStep(int64_t t, Rollout& rollout) {
  const int64_t m = rollout.m;
  // Plain stores: a tensor op per element would cost more than a step.
  float* reward_row = rollout.rewards.data_ptr<float>() + t * m;
  bool* terminated_row = rollout.terminated.data_ptr<bool>() + t * m;
  bool* truncated_row = rollout.truncated.data_ptr<bool>() + t * m;
  const size_t state_size = core_states_.size() / m;
  for (int64_t i = 0; i < m; ++i) {
    reward_row[i] = static_cast<float>(envs_->rewards()[i]);
    terminated_row[i] = envs_->terminated()[i] != 0;
    truncated_row[i] = envs_->truncated()[i] != 0;
    // The environment reset: the next step starts an episode.
    if (terminated_row[i] || truncated_row[i]) {
      std::fill_n(core_states_.begin() + i * state_size, state_size, 0.0f);
    }
  }
  for (const FinishedEpisode& episode : envs_->finished()) {
    Segment& segment = rollout.segments[episode.env_index];
    segment.episode_returns.push_back(episode.episode_return);
    segment.episode_lengths.push_back(episode.length);
    if (episode.truncated) {
      rollout.finals[episode.env_index].push_back(
          ObservationTensor(spec(),
                            envs_->final_observations().data() +
                                episode.env_index * rollout.obs,
                            1)
              .squeeze(0));
    }
  }
  StoreObservations(envs_->observations(), rollout.observations[t + 1]);
}

absl::Status ActorCore::SendSegments(Rollout& rollout, SegmentSink& sink) {
  for (int64_t i = 0; i < rollout.m; ++i) {
    Segment& segment = rollout.segments[i];
    segment.actor_id = stream_actor_id_;
    segment.env_slot = i;
    segment.sequence = next_sequence_[i]++;
    segment.policy_version = version_;
    segment.observations = rollout.observations.select(1, i).clone();
    segment.actions = rollout.actions.select(1, i).clone();
    segment.behaviour_log_probs = rollout.log_probs.select(1, i).clone();
    segment.rewards = rollout.rewards.select(1, i).clone();
    segment.terminated = rollout.terminated.select(1, i).clone();
    segment.truncated = rollout.truncated.select(1, i).clone();
    segment.final_observations =
        rollout.finals[i].empty()
            ? at::empty({0, rollout.obs}, rollout.observation_dtype)
            : at::stack(rollout.finals[i]);
    if (rollout.core_states.defined()) {
      segment.core_state = rollout.core_states[i].clone();
    }
    if (rollout.action_masks.defined()) {
      segment.action_masks = rollout.action_masks.select(1, i).clone();
    }
    if (absl::Status status = sink.Send(std::move(segment)); !status.ok()) {
      return status;
    }
  }
  return absl::OkStatus();
}

absl::StatusOr<std::string> ActorCore::SaveState() const {
  absl::StatusOr<std::string> envs = envs_->SaveState();
  if (!envs.ok()) return envs.status();
  StateWriter writer(kStateKind, kStateVersion);
  writer.PutBytes(config_.env);
  writer.PutI64(config_.num_envs);
  writer.PutI64(config_.actor_id);
  writer.PutI64(env_steps_);
  writer.PutI64s(next_sequence_);
  writer.PutBytes(GeneratorState(generator_));
  writer.PutBytes(*envs);
  // Only a recurrent policy's: a feed-forward actor's state is as before.
  if (!core_states_.empty()) {
    writer.PutDoubles(
        std::vector<double>(core_states_.begin(), core_states_.end()));
  }
  return std::move(writer).Finish();
}

absl::Status ActorCore::RestoreState(absl::string_view state) {
  const std::string context =
      absl::StrCat("actor ", config_.actor_id, " (", config_.env, "): state");
  StateReader reader(state, kStateKind, kStateVersion, context);
  reader.ExpectEqual("the environment", reader.GetBytes("env"), config_.env);
  reader.ExpectEqual("num_envs", reader.GetI64("num_envs"), config_.num_envs);
  reader.ExpectEqual("actor_id", reader.GetI64("actor_id"), config_.actor_id);
  const int64_t env_steps = reader.GetI64("env_steps");
  std::vector<int64_t> next_sequence =
      reader.GetI64s("next_sequence", next_sequence_.size());
  const absl::string_view generator = reader.GetBytes("sampling generator");
  const absl::string_view envs = reader.GetBytes("environments");
  const std::vector<double> core_states =
      ReadCoreStates(reader, core_states_.size());
  reader.Check(env_steps >= 0, absl::StrCat("env_steps is ", env_steps));
  reader.Check(std::all_of(next_sequence.begin(), next_sequence.end(),
                           [](int64_t sequence) { return sequence >= 0; }),
               "a negative sequence number");
  const size_t generator_size = GeneratorState(generator_).size();
  reader.Check(
      generator.size() == generator_size,
      absl::StrCat("the sampling generator state holds ", generator.size(),
                   " bytes, expected ", generator_size));
  if (absl::Status status = reader.Finish(); !status.ok()) return status;

  // Try the generator state on a copy first: LibTorch refuses a bad one
  // only by throwing, and nothing may change before the environments have
  // accepted theirs.
  at::Tensor generator_state = at::empty(
      {static_cast<int64_t>(generator.size())}, at::TensorOptions(at::kByte));
  std::memcpy(generator_state.data_ptr<uint8_t>(), generator.data(),
              generator.size());
  at::Generator trial = generator_.clone();
  try {
    trial.set_state(generator_state);
  } catch (const c10::Error& error) {
    return absl::InvalidArgumentError(absl::StrCat(
        context,
        ": bad sampling generator state: ", error.what_without_backtrace()));
  }
  if (!trial.get<at::CPUGeneratorImpl>()->engine().is_valid()) {
    return absl::InvalidArgumentError(
        absl::StrCat(context, ": bad sampling generator state"));
  }
  if (absl::Status status = envs_->RestoreState(envs); !status.ok()) {
    return status;
  }
  {
    std::lock_guard<std::mutex> lock(generator_.mutex());
    generator_.set_state(generator_state);
  }
  env_steps_ = env_steps;
  next_sequence_ = std::move(next_sequence);
  std::copy(core_states.begin(), core_states.end(), core_states_.begin());
  return absl::OkStatus();
}

}  // namespace vantage
