#include "actor/vector_env.h"

#include <algorithm>
#include <cstdio>
#include <set>
#include <string>
#include <utility>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "absl/synchronization/mutex.h"
#include "actor/envs/env_registry.h"
#include "common/util/state_bytes.h"

namespace vantage {
namespace {

constexpr char kStateKind[] = "vector_env";
constexpr uint32_t kStateVersion = 1;

// Each distinct message once per process on stderr: every checkpoint of a
// run repeats what the first one said.
void SayOnce(absl::string_view message) {
  static absl::Mutex mutex(absl::kConstInit);
  static auto* said = new std::set<std::string>;
  absl::MutexLock lock(&mutex);
  if (!said->insert(std::string(message)).second) return;
  std::fprintf(stderr, "%s\n", std::string(message).c_str());
}

absl::string_view AsBytes(const std::vector<uint8_t>& flags) {
  return absl::string_view(reinterpret_cast<const char*>(flags.data()),
                           flags.size());
}

}  // namespace

absl::StatusOr<std::unique_ptr<VectorEnv>> VectorEnv::Create(
    absl::string_view name, int count, uint64_t seed,
    const EnvOptions& options) {
  if (count < 1) {
    return absl::InvalidArgumentError(
        absl::StrCat("a vector of environments needs count >= 1, got ", count));
  }
  std::vector<std::unique_ptr<Environment>> envs;
  for (int i = 0; i < count; ++i) {
    absl::StatusOr<std::unique_ptr<Environment>> env =
        MakeEnvironment(name, options);
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
  action_width_ = s.action_width();
  const size_t m = envs_.size();
  observations_.resize(m * observation_size_);
  final_observations_.resize(m * observation_size_);
  rewards_.resize(m);
  terminated_.resize(m);
  truncated_.resize(m);
  episode_returns_.resize(m);
  episode_lengths_.resize(m);
  if (s.action_masks) {
    action_masks_.resize(m * s.action_size);
    action_heads_ = s.action_heads();
  }
}

absl::Status VectorEnv::ResetOne(int index) {
  episode_returns_[index] = 0.0;
  episode_lengths_[index] = 0;
  if (absl::Status status = envs_[index]->Reset(
          seeds_(), absl::MakeSpan(observations_)
                        .subspan(index * observation_size_, observation_size_));
      !status.ok()) {
    return status;
  }
  return ReadMask(index);
}

absl::Status VectorEnv::ReadMask(int index) {
  if (action_masks_.empty()) return absl::OkStatus();
  const int64_t n = spec().action_size;
  absl::Span<uint8_t> mask =
      absl::MakeSpan(action_masks_).subspan(index * n, n);
  absl::Status status = envs_[index]->ActionMask(mask);
  if (status.ok()) status = CheckActionMask(spec(), mask);
  // An env without a usable mask has no action to take until it resets.
  if (!status.ok()) std::fill(mask.begin(), mask.end(), 0);
  return status;
}

absl::Status VectorEnv::CheckLegal(int index,
                                   absl::Span<const double> action) const {
  if (action_masks_.empty()) return absl::OkStatus();
  const std::vector<int64_t>& heads = action_heads_;
  const uint8_t* mask = action_masks_.data() + index * spec().action_size;
  for (size_t h = 0; h < heads.size(); mask += heads[h], ++h) {
    // The env's own CheckAction names a value out of range.
    if (!(action[h] >= 0) || action[h] >= static_cast<double>(heads[h])) {
      continue;
    }
    if (!mask[static_cast<int64_t>(action[h])]) {
      return absl::InvalidArgumentError(absl::StrCat(
          spec().name, ": action ",
          heads.size() > 1 ? absl::StrCat("value ", h, " ") : "", action[h],
          " is illegal in this state (its action mask is 0)"));
    }
  }
  return absl::OkStatus();
}

absl::Status VectorEnv::Reset() {
  finished_.clear();
  for (int i = 0; i < size(); ++i) {
    if (absl::Status status = ResetOne(i); !status.ok()) return status;
  }
  return absl::OkStatus();
}

absl::StatusOr<StepResult> VectorEnv::StepOne(int index,
                                              absl::Span<const double> action,
                                              absl::Span<double> observation) {
  if (absl::Status legal = CheckLegal(index, action); !legal.ok()) {
    return legal;
  }
  absl::StatusOr<StepResult> result = envs_[index]->Step(action, observation);
  if (!result.ok() || result->terminated || result->truncated) return result;
  // An episode that ended has no mask until its reset reads one.
  if (absl::Status status = ReadMask(index); !status.ok()) return status;
  return result;
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
    const absl::Span<const double> action =
        actions.subspan(i * action_width_, action_width_);
    absl::StatusOr<StepResult> result = StepOne(i, action, observation);
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

absl::StatusOr<std::string> VectorEnv::SaveState() const {
  StateWriter writer(kStateKind, kStateVersion);
  writer.PutBytes(spec().name);
  writer.PutI64(size());
  writer.PutI64(observation_size_);
  writer.PutI64(action_width_);
  writer.PutEngine(seeds_);
  writer.PutDoubles(observations_);
  writer.PutDoubles(final_observations_);
  writer.PutDoubles(rewards_);
  writer.PutBytes(AsBytes(terminated_));
  writer.PutBytes(AsBytes(truncated_));
  writer.PutDoubles(episode_returns_);
  writer.PutI64s(episode_lengths_);
  writer.PutI64(static_cast<int64_t>(finished_.size()));
  for (const FinishedEpisode& episode : finished_) {
    writer.PutI64(episode.env_index);
    writer.PutDouble(episode.episode_return);
    writer.PutI64(episode.length);
    writer.PutBool(episode.truncated);
  }
  // The environments' states come last, one field each; empty for one
  // that cannot save itself (a Python env without get_state()), whose
  // episode restarts when the state is restored.
  for (const std::unique_ptr<Environment>& env : envs_) {
    absl::StatusOr<std::string> state = env->SaveState();
    if (absl::IsUnimplemented(state.status())) {
      SayOnce(state.status().message());
      writer.PutBytes("");
      continue;
    }
    if (!state.ok()) return state.status();
    writer.PutBytes(*state);
  }
  return std::move(writer).Finish();
}

absl::Status VectorEnv::RestoreEnvironments(
    const std::vector<absl::string_view>& env_states) {
  // Each environment restores all or nothing, but one may refuse after
  // others took their new state: keep what they had to roll them back.
  std::vector<std::string> backups;
  for (size_t i = 0; i < env_states.size(); ++i) {
    if (env_states[i].empty()) {
      backups.emplace_back();
      continue;
    }
    absl::StatusOr<std::string> backup = envs_[i]->SaveState();
    if (!backup.ok()) return backup.status();
    backups.push_back(std::move(*backup));
  }
  for (size_t i = 0; i < env_states.size(); ++i) {
    if (env_states[i].empty()) continue;
    absl::Status status = envs_[i]->RestoreState(env_states[i]);
    if (status.ok()) continue;
    for (size_t j = 0; j < i; ++j) {
      if (env_states[j].empty()) continue;
      if (absl::Status undo = envs_[j]->RestoreState(backups[j]); !undo.ok()) {
        return absl::InternalError(absl::StrCat(
            "env ", i, " refused its state (", status.message(),
            ") and rolling back env ", j, " failed: ", undo.message()));
      }
    }
    return absl::Status(status.code(),
                        absl::StrCat("env ", i, ": ", status.message()));
  }
  return absl::OkStatus();
}

// A state blob read and checked but not yet applied: nothing may change
// before the environments have accepted their states.
struct VectorEnv::SavedState {
  std::mt19937_64 seeds;
  std::vector<double> observations;
  std::vector<double> final_observations;
  std::vector<double> rewards;
  absl::string_view terminated;
  absl::string_view truncated;
  std::vector<double> returns;
  std::vector<int64_t> lengths;
  std::vector<FinishedEpisode> finished;
  std::vector<absl::string_view> env_states;
};

absl::Status VectorEnv::RestoreState(absl::string_view state) {
  absl::StatusOr<SavedState> saved = ReadState(state);
  if (!saved.ok()) return saved.status();
  return ApplyState(*saved);
}

absl::StatusOr<VectorEnv::SavedState> VectorEnv::ReadState(
    absl::string_view state) const {
  const size_t m = envs_.size();
  StateReader reader(state, kStateKind, kStateVersion,
                     absl::StrCat("vector of ", spec().name, ": state"));
  reader.ExpectEqual("the environment", reader.GetBytes("name"), spec().name);
  reader.ExpectEqual("the number of environments", reader.GetI64("size"),
                     size());
  reader.ExpectEqual("observation_size", reader.GetI64("observation_size"),
                     observation_size_);
  reader.ExpectEqual("the action width", reader.GetI64("action_width"),
                     action_width_);
  SavedState saved;
  saved.seeds = reader.GetEngine("episode seeds");
  const size_t values = m * observation_size_;
  saved.observations = reader.GetDoubles("observations", values);
  saved.final_observations = reader.GetDoubles("final_observations", values);
  saved.rewards = reader.GetDoubles("rewards", m);
  saved.terminated = reader.GetBytes("terminated");
  saved.truncated = reader.GetBytes("truncated");
  saved.returns = reader.GetDoubles("episode_returns", m);
  saved.lengths = reader.GetI64s("episode_lengths", m);
  saved.finished = ReadFinishedEpisodes(reader);
  for (size_t i = 0; i < m; ++i) {
    saved.env_states.push_back(
        reader.GetBytes(absl::StrCat("env ", i, " state")));
  }
  const auto flags_ok = [m](absl::string_view flags) {
    return flags.size() == m &&
           std::all_of(flags.begin(), flags.end(),
                       [](char flag) { return flag == 0 || flag == 1; });
  };
  reader.Check(flags_ok(saved.terminated) && flags_ok(saved.truncated),
               absl::StrCat("the step flags are not ", m, " bools each"));
  reader.Check(std::all_of(saved.lengths.begin(), saved.lengths.end(),
                           [](int64_t length) { return length >= 0; }),
               "a negative episode length");
  if (absl::Status status = reader.Finish(); !status.ok()) return status;
  return saved;
}

std::vector<FinishedEpisode> VectorEnv::ReadFinishedEpisodes(
    StateReader& reader) const {
  const int64_t finished_count = reader.GetI64("finished episodes");
  reader.Check(
      finished_count >= 0 && finished_count <= size(),
      absl::StrCat(finished_count, " episodes finished in one step of ",
                   envs_.size(), " environments"));
  std::vector<FinishedEpisode> finished;
  for (int64_t i = 0; reader.status().ok() && i < finished_count; ++i) {
    const int64_t index = reader.GetI64("finished env_index");
    FinishedEpisode episode;
    episode.episode_return = reader.GetDouble("finished episode_return");
    episode.length = reader.GetI64("finished length");
    episode.truncated = reader.GetBool("finished truncated");
    reader.Check(index >= 0 && index < size() && episode.length >= 1,
                 absl::StrCat("finished episode ", i, " is impossible (env ",
                              index, ", length ", episode.length, ")"));
    episode.env_index = static_cast<int>(index);
    finished.push_back(episode);
  }
  return finished;
}

absl::Status VectorEnv::ApplyState(SavedState& saved) {
  if (absl::Status status = RestoreEnvironments(saved.env_states);
      !status.ok()) {
    return status;
  }
  seeds_ = saved.seeds;
  observations_ = std::move(saved.observations);
  final_observations_ = std::move(saved.final_observations);
  rewards_ = std::move(saved.rewards);
  terminated_.assign(saved.terminated.begin(), saved.terminated.end());
  truncated_.assign(saved.truncated.begin(), saved.truncated.end());
  episode_returns_ = std::move(saved.returns);
  episode_lengths_ = std::move(saved.lengths);
  finished_ = std::move(saved.finished);
  for (size_t i = 0; i < envs_.size(); ++i) {
    if (!saved.env_states[i].empty()) {
      // A mask is the restored state's, which the environment knows again.
      if (absl::Status status = ReadMask(static_cast<int>(i)); !status.ok()) {
        return status;
      }
      continue;
    }
    SayOnce(absl::StrCat(spec().name,
                         " saved no state: its episodes restart on resume"));
    if (absl::Status status = ResetOne(static_cast<int>(i)); !status.ok()) {
      return status;
    }
  }
  return absl::OkStatus();
}

}  // namespace vantage
