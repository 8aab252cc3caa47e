#ifndef VANTAGE_ACTOR_ENVS_MUJOCO_MUJOCO_ENV_H_
#define VANTAGE_ACTOR_ENVS_MUJOCO_MUJOCO_ENV_H_

#include <random>

#include "actor/envs/mujoco/mujoco_model.h"
#include "common/env/environment.h"

namespace vantage {

// The shared part of every MuJoCo task: seeding, resetting, clipping the
// action into ctrl, frame skip, and turning MuJoCo errors and numerical
// blow-ups into errors. Tasks supply the observation, the reset noise and
// the reward and termination rules.
class MujocoEnv : public Environment {
 public:
  const EnvSpec& spec() const override { return spec_; }
  absl::Status Reset(uint64_t seed, absl::Span<double> observation) override;
  absl::StatusOr<StepResult> Step(absl::Span<const double> action,
                                  absl::Span<double> observation) override;

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

  mjData* mutable_data() { return data_.get(); }

  // The usual ResetState: qpos += U(-scale, scale) and qvel +=
  // U(-scale, scale) or, with normal_qvel, scale * N(0, 1).
  void PerturbState(std::mt19937_64& rng, double scale, bool normal_qvel);

 private:
  EnvSpec spec_;
  MjModelPtr model_;
  MjDataPtr data_;
  int frame_skip_;
  std::mt19937_64 rng_;
  std::vector<double> clipped_;
  // Set after an error left the simulation in an unknown state.
  bool needs_reset_ = true;
};

}  // namespace vantage

#endif  // VANTAGE_ACTOR_ENVS_MUJOCO_MUJOCO_ENV_H_
