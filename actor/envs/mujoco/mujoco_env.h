#ifndef VANTAGE_ACTOR_ENVS_MUJOCO_MUJOCO_ENV_H_
#define VANTAGE_ACTOR_ENVS_MUJOCO_MUJOCO_ENV_H_

#include <memory>
#include <random>
#include <string>
#include <vector>

#include "actor/envs/mujoco/mujoco_model.h"
#include "common/env/environment.h"

namespace vantage {

class MujocoRenderer;
class StateReader;

// The shared part of every MuJoCo task: seeding, resetting, clipping the
// action into ctrl, frame skip, and turning MuJoCo errors and numerical
// blow-ups into errors. Tasks supply the observation, the reset noise and
// the reward and termination rules.
class MujocoEnv : public Environment {
 public:
  ~MujocoEnv() override;

  const EnvSpec& spec() const override { return spec_; }
  absl::Status Reset(uint64_t seed, absl::Span<double> observation) override;
  absl::StatusOr<StepResult> Step(absl::Span<const double> action,
                                  absl::Span<double> observation) override;
  // MuJoCo 2.2.2 has no mj_getState: the blob holds mjData's scalars that
  // outlive a step (time, constraint counts, warnings) and its whole buffer
  // (qpos, qvel, act, ctrl, the solver's warm start, contacts and the
  // derived quantities observations read; packed, as it is mostly unused
  // constraint rows), the reset generator, whether a reset is due, and the
  // task's own state (SaveTaskState). The buffer is only meaningful for the
  // same compiled model and MuJoCo version, so restoring checks both: the
  // version, the model's sizes and a fingerprint of the model.
  absl::StatusOr<std::string> SaveState() const override;
  absl::Status RestoreState(absl::string_view state) override;
  // MuJoCo's own renderer on an offscreen OSMesa context
  // (actor/envs/mujoco/mujoco_renderer.h), made at the first call and again
  // when the size changes. Needs a running episode.
  absl::StatusOr<Frame> Render(int width, int height) override;

  const mjModel* model() const { return model_.get(); }
  const mjData* data() const { return data_.get(); }
  // Physics steps per environment step.
  int frame_skip() const { return frame_skip_; }

 protected:
  // `spec` needs name, observation_size and max_episode_steps; the action
  // part and control_dt come from the model (actuator ctrlrange; actuators
  // without a limit are unbounded).
  MujocoEnv(EnvSpec spec, MjModelPtr model, MjDataPtr data, int frame_skip);

  // Called after mj_resetData, before mj_forward: perturb qpos/qvel.
  virtual void ResetState(std::mt19937_64& rng) {}
  // Called with the clipped action before the physics steps.
  virtual void BeforeStep() {}
  // Reward and termination once the physics has stepped.
  virtual StepResult Evaluate(absl::Span<const double> action) = 0;
  virtual void Observe(double* observation) const = 0;

  // State a task keeps outside mjData that outlives a Step, as a blob of
  // its own; the default has none.
  virtual std::string SaveTaskState() const { return {}; }
  // Restores what SaveTaskState wrote, all or nothing: it runs once the
  // rest of the environment's blob has been checked, and the rest is
  // applied only if it succeeds.
  virtual absl::Status RestoreTaskState(absl::string_view state);

  // The body a video's camera follows side-on (a character's root), or -1
  // for the model's fixed camera or a view of the whole model.
  virtual int TrackedBody() const { return -1; }

  mjData* mutable_data() { return data_.get(); }

  // The usual ResetState: qpos += U(-scale, scale) and qvel +=
  // U(-scale, scale) or, with normal_qvel, scale * N(0, 1).
  void PerturbState(std::mt19937_64& rng, double scale, bool normal_qvel);

 private:
  // RestoreState's blob read and checked, before anything is changed
  // (defined in the .cc).
  struct SavedState;
  absl::StatusOr<SavedState> ReadState(absl::string_view state) const;
  // Counts out of range would make later reads of the contact and
  // constraint arrays overrun the buffer, or not fit mjData's ints.
  void CheckCounts(const SavedState& saved, StateReader& reader) const;
  void ApplyState(const SavedState& saved);

  EnvSpec spec_;
  MjModelPtr model_;
  MjDataPtr data_;
  int frame_skip_;
  // Of the compiled model (its MJB bytes): a state is refused by a model
  // that differs in anything, not just in the sizes of mjData's buffer.
  uint64_t model_fingerprint_ = 0;
  std::mt19937_64 rng_;
  // Scratch of one Step, not state.
  std::vector<double> clipped_;
  // Set after an error left the simulation in an unknown state.
  bool needs_reset_ = true;
  // Made by the first Render.
  std::unique_ptr<MujocoRenderer> renderer_;
};

}  // namespace vantage

#endif  // VANTAGE_ACTOR_ENVS_MUJOCO_MUJOCO_ENV_H_
