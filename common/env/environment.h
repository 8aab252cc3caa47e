#ifndef VANTAGE_COMMON_ENV_ENVIRONMENT_H_
#define VANTAGE_COMMON_ENV_ENVIRONMENT_H_

// The environment interface actors step and the spec the learner receives.
// Physics engines live behind it in actor/envs; nothing here links them.

#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "absl/types/span.h"
#include "common/env/frame.h"

namespace vantage {

// One entry of a Dict (or Tuple) observation, in the flat row every
// observation is: the entries side by side in the spec's order.
struct ObservationKey {
  std::string name;  // the Dict's key ("0", "1", ... of a Tuple)
  int64_t size = 0;  // values in the row
  // An image: [channels, height, width] (product: size) of integers in
  // [0, high], which enter the networks divided by high through a
  // convolutional torso of its own. Empty (and high 0): a vector, which is
  // normalised like every vector observation.
  std::vector<int64_t> shape;
  int64_t high = 0;
  bool image() const { return !shape.empty(); }
};

struct EnvSpec {
  std::string name;
  int64_t observation_size = 0;  // observations are flat [observation_size]
  // A Dict or Tuple observation: its entries, whose sizes sum to
  // observation_size (then observation_shape is empty and
  // observation_high 0: the row is float32 on the wire). Empty: one
  // vector or image observation as below.
  std::vector<ObservationKey> observation_keys;
  // Images (pixels, MinAtar's grids): [channels, height, width], whose
  // product is observation_size, for convolutional torsos; empty for
  // vectors.
  std::vector<int64_t> observation_shape;
  // > 0: every observation value is an integer in [0, observation_high]
  // (<= 255); such observations travel and are batched as uint8, are never
  // normalised, and enter the networks divided by observation_high.
  // 0: real-valued vectors, float32 on the wire, normalised.
  int64_t observation_high = 0;
  bool discrete = false;
  // Continuous: the action dimension, with [action_low, action_high] bounds.
  // Discrete: the number of actions, and the bounds are empty.
  int64_t action_size = 0;
  std::vector<double> action_low;
  std::vector<double> action_high;
  // Several discrete choices at once (Gymnasium's MultiDiscrete, and
  // MultiBinary as choices of 2): the number of choices of each of the
  // action's values, with discrete true and action_size their sum (the
  // policy's logits, one categorical head per value). Empty for Discrete
  // (one value of action_size choices) and continuous actions.
  std::vector<int64_t> action_nvec;
  // Discrete only: at every step the environment says which actions are
  // legal (Environment::ActionMask, action_size entries: each head's
  // choices in turn); actors sample only those and the learner scores the
  // policy on them alone.
  bool action_masks = false;
  // Steps after which the time limit truncates an episode (0: none).
  int64_t max_episode_steps = 1000;
  // Simulated seconds per step (physics timestep x frame skip).
  double control_dt = 0.0;

  // "continuous:6", "discrete:4", "multidiscrete:3x2" or
  // "discrete:4 masked".
  std::string ActionString() const;
  // Values per action: 1 (Discrete), one per head (MultiDiscrete), or the
  // continuous dimension.
  int64_t action_width() const;
  // The discrete heads' choices: {action_size} for Discrete, action_nvec
  // for MultiDiscrete; empty for continuous actions.
  std::vector<int64_t> action_heads() const;
  bool byte_observations() const { return observation_high > 0; }
  // "17", "uint8 4x10x10" or "dict(camera: uint8 3x8x8, joints: 7)".
  std::string ObservationString() const;
};

struct StepResult {
  double reward = 0.0;
  // s_{t+1} is terminal: the learner bootstraps with 0.
  bool terminated = false;
  // A time limit ended the episode; the observation written by Step is the
  // final one, which the learner bootstraps from.
  bool truncated = false;
};

// One environment instance; not thread-safe. Observation spans must hold
// spec().observation_size values, actions spec().action_size (discrete: one
// value holding the action index).
class Environment {
 public:
  virtual ~Environment() = default;

  virtual const EnvSpec& spec() const = 0;

  // Starts an episode deterministically from `seed` and writes its first
  // observation.
  virtual absl::Status Reset(uint64_t seed, absl::Span<double> observation) = 0;

  // Applies `action` (continuous actions are clipped to the bounds; a
  // non-finite or wrongly sized action is an InvalidArgument error) and
  // writes the next observation. Never resets by itself.
  virtual absl::StatusOr<StepResult> Step(absl::Span<const double> action,
                                          absl::Span<double> observation) = 0;

  // Everything that decides what later Reset and Step calls produce, as an
  // opaque blob (see common/util/state_bytes.h) for checkpoints; valid at
  // any point between calls, including before the first Reset and after an
  // episode ended. The defaults say the environment cannot.
  virtual absl::StatusOr<std::string> SaveState() const;
  // Puts the environment into exactly the saved state: the same actions
  // then give bit-identical observations, rewards and flags. The blob must
  // come from an environment of the same name and model; anything else is
  // InvalidArgument and leaves this environment as it was.
  virtual absl::Status RestoreState(absl::string_view state);

  // Which actions are legal in the current state (after Reset, Step or
  // RestoreState): mask[i] = 1 for a legal action i, 0 for an illegal
  // one, spec().action_size entries of which at least one is 1. Only
  // environments whose spec says action_masks have one; the default says
  // it has none.
  virtual absl::Status ActionMask(absl::Span<uint8_t> mask) const;

  // A picture of the current state, `width` x `height` pixels (both >= 1),
  // for videos of episodes. It only reads the simulation: rendering or not
  // changes nothing the environment later produces. The default says the
  // environment cannot.
  virtual absl::StatusOr<Frame> Render(int width, int height);
};

// Checks an action's size and finiteness against the spec (and, if
// discrete, that each value is an integer in its head's range); the
// message names the entry.
absl::Status CheckAction(const EnvSpec& spec, absl::Span<const double> action);

// A mask as Environment::ActionMask must write it: action_size entries,
// each 0 or 1, at least one 1 in every head, for a spec with action_masks. The
// message names what is wrong.
absl::Status CheckActionMask(const EnvSpec& spec,
                             absl::Span<const uint8_t> mask);

// `env`'s mask for its current state, checked (CheckActionMask); empty
// when its spec has no action masks.
absl::StatusOr<std::vector<uint8_t>> ReadActionMask(const Environment& env);

// The action fields agree: action_nvec is empty, or belongs to discrete
// actions with each value's choices >= 1 and their sum action_size. The
// message names the field.
absl::Status CheckActionLayout(const EnvSpec& spec);

// The observation fields agree: observation_shape is empty or three
// positive dimensions whose product is observation_size, and
// observation_high is in [0, 255]; Dict entries have distinct non-empty
// names, sizes summing to observation_size, and images of three positive
// dimensions with high in [1, 255] (vectors: none, high 0). The message
// names the field.
absl::Status CheckObservationLayout(const EnvSpec& spec);

// The observation buffer a Reset or Step writes holds the spec's size.
absl::Status CheckObservationBuffer(const EnvSpec& spec,
                                    absl::Span<double> observation);

// What every Step checks before touching its physics: an episode is under
// way (FailedPrecondition otherwise), the action passes CheckAction and the
// observation buffer has the spec's size.
absl::Status CheckStep(const EnvSpec& spec, bool needs_reset,
                       absl::Span<const double> action,
                       absl::Span<double> observation);

}  // namespace vantage

#endif  // VANTAGE_COMMON_ENV_ENVIRONMENT_H_
