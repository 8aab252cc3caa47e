#ifndef VANTAGE_ACTOR_ENVS_BULLET_BULLET_ENV_H_
#define VANTAGE_ACTOR_ENVS_BULLET_BULLET_ENV_H_

#include <cstdint>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "actor/envs/bullet/bullet_world.h"
#include "common/env/environment.h"

namespace vantage {

// The shared part of the Bullet tasks: a planar model, one torque per hinge
// (action in [-1, 1] times the hinge's gear), a fixed physics timestep and
// frame skip, and errors for bad actions and numerical blow-ups. Tasks
// supply the reset noise, observation, reward and termination.
//
// Determinism: every Reset builds a fresh BulletWorld, so no cache of an
// earlier episode (contact manifolds, the solver's warm start, broadphase
// pairs) reaches the new one; the same seed and actions then give
// bit-identical observations.
class BulletEnv : public Environment {
 public:
  const EnvSpec& spec() const override { return spec_; }
  absl::Status Reset(uint64_t seed, absl::Span<double> observation) override;
  absl::StatusOr<StepResult> Step(absl::Span<const double> action,
                                  absl::Span<double> observation) override;
  // A replay log: the episode's reset seed and every clipped action applied
  // since (plus whether a reset is due, and the positions and velocities
  // they led to). Restoring rebuilds the world with Reset(seed) and replays
  // the actions, which is exact because stepping is deterministic, and
  // then checks that the replay reproduced the saved positions and
  // velocities bit for bit (a blob from another Bullet build would not).
  // The log grows by one action per step until the next Reset, so an
  // unlimited episode's blob and restore time grow with it; the registered
  // tasks stop after 1000 steps.
  absl::StatusOr<std::string> SaveState() const override;
  absl::Status RestoreState(absl::string_view state) override;
  // Side-on, drawn from the capsules (actor/render/planar_drawing.h); the
  // view follows the root link. Needs a running episode.
  absl::StatusOr<Frame> Render(int width, int height) override;

  const PlanarModel& model() const { return model_; }
  // N m per unit of action, one per hinge.
  const std::vector<double>& gears() const { return gears_; }
  int frame_skip() const { return frame_skip_; }
  // The model's zero pose: every coordinate 0 but the root height.
  std::vector<double> ZeroPose() const;
  // The running episode's world (nullptr before the first Reset).
  const BulletWorld* world() const { return world_.get(); }

 protected:
  // `spec` needs name, observation_size and max_episode_steps; the action
  // part (one per hinge, [-1, 1]) and control_dt come from the model. The
  // model must be valid (ValidatePlanarModel) with one gear per hinge.
  BulletEnv(EnvSpec spec, PlanarModel model, std::vector<double> gears,
            int frame_skip);

  // The episode's ground, drawn before the world is built (by default the
  // model's own, drawing nothing from `rng`).
  virtual void ShapeGround(std::mt19937_64& rng, PlanarModel& model) {}
  // Perturbs the initial positions and velocities (num_dofs each), which
  // start at ZeroPose() and 0.
  virtual void ResetState(std::mt19937_64& rng, std::vector<double>& q,
                          std::vector<double>& qd) = 0;
  // Called once the world stands in its initial state, and with the
  // clipped action before the physics steps.
  virtual void BeginEpisode(const BulletWorld& world) {}
  virtual void BeforeStep(const BulletWorld& world) {}
  // Reward and termination once the physics has stepped.
  virtual StepResult Evaluate(const BulletWorld& world,
                              absl::Span<const double> action) = 0;
  virtual void Observe(const BulletWorld& world, double* observation) const = 0;
  // Whatever else decides the task's rules (thresholds set by a config),
  // so that a state is only restored into an identical task.
  virtual std::string TaskSignature() const { return {}; }
  // The hinge torques for the next TorqueSubsteps() physics steps of a
  // frame; by default the clipped action times the gears, held for the
  // whole frame. A controller (PD) recomputes them more often.
  virtual int TorqueSubsteps() const { return frame_skip_; }
  virtual void Torques(const BulletWorld& world,
                       absl::Span<const double> clipped,
                       std::vector<double>& torques) const;
  // Replaces the [-1, 1] action bounds (one entry per hinge).
  void SetActionBounds(std::vector<double> low, std::vector<double> high);

 private:
  void Begin(uint64_t seed);
  // One step of the clipped action: physics, blow-up check, Evaluate.
  absl::Status Advance(absl::Span<const double> clipped, StepResult* result);
  // Reset(seed) and the logged actions, as Step applied them.
  absl::Status Replay(uint64_t seed, absl::Span<const double> log);
  // What a state must match: the model, gears, frame skip and task.
  uint64_t Signature() const;
  // RestoreState's blob read and checked, before anything is changed
  // (defined in the .cc).
  struct SavedState;
  absl::StatusOr<SavedState> ReadState(absl::string_view state,
                                       const std::string& context) const;
  // Replay applies logged actions as already clipped: one outside the
  // bounds can only come from a bad blob.
  absl::Status CheckActionLog(const std::vector<double>& log,
                              const std::string& context) const;
  // Replays the saved episode; one that does not end bit for bit where the
  // saved one did is undone.
  absl::Status ReplayState(const SavedState& saved, const std::string& context);

  EnvSpec spec_;
  PlanarModel model_;
  std::vector<double> gears_;
  int frame_skip_;
  std::unique_ptr<BulletWorld> world_;
  uint64_t seed_ = 0;
  // Clipped actions since the last Reset, row after row.
  std::vector<double> log_;
  // Before the first Reset and after an error left the world unknown.
  bool needs_reset_ = true;
  // Scratch of one Step, not state.
  std::vector<double> clipped_;
  std::vector<double> torques_;
};

}  // namespace vantage

#endif  // VANTAGE_ACTOR_ENVS_BULLET_BULLET_ENV_H_
