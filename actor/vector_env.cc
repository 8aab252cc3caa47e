#include "actor/vector_env.h"

#include <algorithm>
#include <utility>

#include "absl/strings/str_cat.h"
#include "actor/envs/env_registry.h"

namespace vantage {

absl::StatusOr<std::unique_ptr<VectorEnv>> VectorEnv::Create(
    absl::string_view name, int count, uint64_t seed) {
  if (count < 1) {
    return absl::InvalidArgumentError(
        absl::StrCat("a vector of environments needs count >= 1, got ", count));
  }
  std::vector<std::unique_ptr<Environment>> envs;
  for (int i = 0; i < count; ++i) {
    absl::StatusOr<std::unique_ptr<Environment>> env = MakeEnvironment(name);
    if (!env.ok()) return env.status();
    envs.push_back(std::move(*env));
  }
  return std::unique_ptr<VectorEnv>(new VectorEnv(std::move(envs), seed));
}

VectorEnv::VectorEnv(std::vector<std::unique_ptr<Environment>> envs,
                     uint64_t seed)
    : envs_(std::move(envs)), seeds_(seed) {
  const EnvSpec& s = spec();
  observation_size_ = s.observation_size;
  action_width_ = s.discrete ? 1 : s.action_size;
  const size_t m = envs_.size();
  observations_.resize(m * observation_size_);
  final_observations_.resize(m * observation_size_);
  rewards_.resize(m);
  terminated_.resize(m);
  truncated_.resize(m);
  episode_returns_.resize(m);
  episode_lengths_.resize(m);
}

absl::Status VectorEnv::ResetOne(int index) {
  episode_returns_[index] = 0.0;
  episode_lengths_[index] = 0;
  return envs_[index]->Reset(
      seeds_(), absl::MakeSpan(observations_)
                    .subspan(index * observation_size_, observation_size_));
}

absl::Status VectorEnv::Reset() {
  finished_.clear();
  for (int i = 0; i < size(); ++i) {
    if (absl::Status status = ResetOne(i); !status.ok()) return status;
  }
  return absl::OkStatus();
}

absl::Status VectorEnv::Step(absl::Span<const double> actions) {
  if (actions.size() != static_cast<size_t>(size() * action_width_)) {
    return absl::InvalidArgumentError(
        absl::StrCat("actions hold ", actions.size(), " values, expected ",
                     size(), " x ", action_width_));
  }
  finished_.clear();
  absl::Status first_error;
  for (int i = 0; i < size(); ++i) {
    absl::Span<double> observation =
        absl::MakeSpan(observations_)
            .subspan(i * observation_size_, observation_size_);
    absl::StatusOr<StepResult> result = envs_[i]->Step(
        actions.subspan(i * action_width_, action_width_), observation);
    if (!result.ok()) {
      // Nothing stale may pass for this step's outcome.
      rewards_[i] = 0.0;
      terminated_[i] = truncated_[i] = 0;
      if (first_error.ok()) {
        first_error = absl::Status(
            result.status().code(),
            absl::StrCat("env ", i, ": ", result.status().message()));
      }
      continue;
    }
    rewards_[i] = result->reward;
    terminated_[i] = result->terminated;
    truncated_[i] = result->truncated;
    episode_returns_[i] += result->reward;
    ++episode_lengths_[i];
    if (result->terminated || result->truncated) {
      std::copy(observation.begin(), observation.end(),
                final_observations_.begin() + i * observation_size_);
      finished_.push_back(
          {i, episode_returns_[i], episode_lengths_[i], !result->terminated});
      if (absl::Status status = ResetOne(i); !status.ok() && first_error.ok()) {
        first_error = status;
      }
    }
  }
  return first_error;
}

}  // namespace vantage
