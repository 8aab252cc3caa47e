#ifndef VANTAGE_ACTOR_VECTOR_ENV_H_
#define VANTAGE_ACTOR_VECTOR_ENV_H_

#include <cstdint>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "absl/types/span.h"
#include "actor/envs/env_registry.h"
#include "common/env/environment.h"

namespace vantage {

class StateReader;

struct FinishedEpisode {
  int env_index = 0;
  double episode_return = 0.0;
  int64_t length = 0;
  bool truncated = false;  // else terminated
};

// M environments of one kind stepped together with automatic reset, all
// results in preallocated row-major buffers (for batched inference).
// After Step, observations() holds each env's next observation; where an
// episode ended that is the new episode's first one and the observation
// that ended it is in final_observations().
class VectorEnv {
 public:
  // Environment `name` (see MakeEnvironment) x `count`; episode seeds are
  // drawn from `seed`, so the same seed replays the same episodes.
  static absl::StatusOr<std::unique_ptr<VectorEnv>> Create(
      absl::string_view name, int count, uint64_t seed,
      const EnvOptions& options = {});

  const EnvSpec& spec() const { return envs_[0]->spec(); }
  int size() const { return static_cast<int>(envs_.size()); }

  absl::Status Reset();
  // actions: [size, action values]. An error names the (first) failing
  // environment, whose reward and flags read 0 and whose episode goes on
  // (or needs the reset the error asks for); the others have stepped and
  // kept their results.
  absl::Status Step(absl::Span<const double> actions);

  absl::Span<const double> observations() const { return observations_; }
  absl::Span<const double> final_observations() const {
    return final_observations_;
  }
  absl::Span<const double> rewards() const { return rewards_; }
  const std::vector<uint8_t>& terminated() const { return terminated_; }
  const std::vector<uint8_t>& truncated() const { return truncated_; }
  // Masked discrete actions (EnvSpec::action_masks): [size, actions], 1
  // where an action is legal in each env's current state; empty otherwise.
  // Step refuses an illegal action.
  const std::vector<uint8_t>& action_masks() const { return action_masks_; }
  // Episodes that ended during the last Step.
  const std::vector<FinishedEpisode>& finished() const { return finished_; }
  // The steps each env's current episode has taken.
  const std::vector<int64_t>& episode_lengths() const {
    return episode_lengths_;
  }

  // Every environment's state, the episode-seed generator, the running
  // episode returns and lengths, and what the accessors above return, so
  // that a restored vector steps and resets exactly like the saved one.
  absl::StatusOr<std::string> SaveState() const;
  // Needs a state of the same environment and size. All or nothing: on any
  // error (InvalidArgument for a bad blob) the vector is left as it was.
  absl::Status RestoreState(absl::string_view state);

 private:
  // RestoreState's blob read and checked, before anything is changed
  // (defined in the .cc).
  struct SavedState;
  // Reads and checks a state without changing anything.
  absl::StatusOr<SavedState> ReadState(absl::string_view state) const;
  std::vector<FinishedEpisode> ReadFinishedEpisodes(StateReader& reader) const;
  // Restores the environments first, as only they can still refuse.
  absl::Status ApplyState(SavedState& saved);
  // Each environment's state (an empty one: none saved, left as it is),
  // all or nothing: one that refuses rolls the others back.
  absl::Status RestoreEnvironments(
      const std::vector<absl::string_view>& env_states);
  VectorEnv(std::vector<std::unique_ptr<Environment>> envs, uint64_t seed);
  absl::Status ResetOne(int index);
  // Env `index` one step, refusing an illegal action, and its next mask.
  absl::StatusOr<StepResult> StepOne(int index, absl::Span<const double> action,
                                     absl::Span<double> observation);
  // Env `index`'s mask for its current state, checked (masked actions only).
  absl::Status ReadMask(int index);
  // Env `index`'s action is legal in its current state (or none are masked).
  absl::Status CheckLegal(int index, absl::Span<const double> action) const;

  std::vector<std::unique_ptr<Environment>> envs_;
  std::mt19937_64 seeds_;
  int64_t observation_size_;
  int64_t action_width_;
  std::vector<double> observations_;
  std::vector<double> final_observations_;
  std::vector<double> rewards_;
  std::vector<uint8_t> terminated_;
  std::vector<uint8_t> truncated_;
  std::vector<uint8_t> action_masks_;
  // Masked actions' heads (EnvSpec::action_heads), read once: stepping
  // checks every action against them.
  std::vector<int64_t> action_heads_;
  std::vector<double> episode_returns_;
  std::vector<int64_t> episode_lengths_;
  std::vector<FinishedEpisode> finished_;
};

}  // namespace vantage

#endif  // VANTAGE_ACTOR_VECTOR_ENV_H_
