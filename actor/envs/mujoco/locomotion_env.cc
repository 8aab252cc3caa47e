#include "actor/envs/mujoco/locomotion_env.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <utility>

#include "absl/strings/str_cat.h"

namespace vantage {
namespace {

class LocomotionEnv : public MujocoEnv {
 public:
  LocomotionEnv(const LocomotionTask& task, EnvSpec spec, MjModelPtr model,
                MjDataPtr data, int forward_body)
      : MujocoEnv(std::move(spec), std::move(model), std::move(data),
                  task.frame_skip),
        task_(task),
        forward_body_(forward_body) {}

 protected:
  void ResetState(std::mt19937_64& rng) override {
    if (task_.qpos_normal_noise > 0 || task_.qvel_normal_noise > 0) {
      std::normal_distribution<double> normal(0.0, 1.0);
      mjData* d = mutable_data();
      for (int i = 0; i < model()->nq; ++i) {
        d->qpos[i] += task_.qpos_normal_noise * normal(rng);
      }
      for (int i = 0; i < model()->nv; ++i) {
        d->qvel[i] += task_.qvel_normal_noise * normal(rng);
      }
      return;
    }
    PerturbState(rng, task_.reset_noise, task_.normal_qvel_noise);
  }

  void BeforeStep() override { x_before_ = ForwardX(); }

  int TrackedBody() const override { return forward_body_; }

  StepResult Evaluate(absl::Span<const double> action) override {
    StepResult result;
    const bool healthy = Healthy();
    // Step leaves positions current (mj_kinematics), not the centres of
    // mass.
    if (task_.subtree_com) mj_comPos(model(), mutable_data());
    if (task_.sparse_x_threshold > -std::numeric_limits<double>::infinity()) {
      const double x =
          task_.sparse_either_way ? std::fabs(ForwardX()) : ForwardX();
      result.reward = x > task_.sparse_x_threshold ? 1.0 : 0.0;
    } else {
      const double velocity = (ForwardX() - x_before_) / spec().control_dt;
      double effort = 0.0;
      for (double a : action) effort += a * a;
      result.reward =
          task_.forward_weight * velocity - task_.ctrl_cost * effort;
      if (healthy || task_.terminate_when_unhealthy) {
        result.reward += task_.healthy_reward;
      }
    }
    result.terminated = task_.terminate_when_unhealthy && !healthy;
    return result;
  }

  void Observe(double* observation) const override {
    const mjModel* m = model();
    const mjData* d = data();
    double* out = observation;
    for (int i = task_.observe_qpos_from; i < m->nq; ++i) *out++ = d->qpos[i];
    for (int i = 0; !task_.hide_velocities && i < m->nv; ++i) {
      *out++ = std::clamp(d->qvel[i], -task_.qvel_clip, task_.qvel_clip);
    }
    if (task_.subtree_com) {
      for (int k = 0; k < 3; ++k)
        *out++ = d->subtree_com[3 * forward_body_ + k];
    }
  }

 private:
  // Without a forward body there is no forward reward and no height rule.
  double ForwardX() const {
    if (forward_body_ < 0) return 0.0;
    return task_.subtree_com ? data()->subtree_com[3 * forward_body_]
                             : data()->xpos[3 * forward_body_];
  }

  bool Healthy() const {
    const mjModel* m = model();
    const mjData* d = data();
    if (forward_body_ >= 0) {
      const double z = d->xpos[3 * forward_body_ + 2];
      if (!(z > task_.min_z && z < task_.max_z)) return false;
    }
    if (task_.angle_index >= 0) {
      const double angle = d->qpos[task_.angle_index];
      if (!(angle > task_.min_angle && angle < task_.max_angle)) return false;
    }
    for (int i = 2; i < m->nq; ++i) {
      if (!(std::fabs(d->qpos[i]) < task_.state_limit)) return false;
    }
    for (int i = 0; i < m->nv; ++i) {
      if (!(std::fabs(d->qvel[i]) < task_.state_limit)) return false;
    }
    return true;
  }

  const LocomotionTask task_;
  const int forward_body_;
  double x_before_ = 0.0;
};

}  // namespace

absl::StatusOr<std::unique_ptr<Environment>> MakeLocomotionEnv(
    const LocomotionTask& task, MjModelPtr model) {
  const int body =
      task.forward_body.empty()
          ? -1
          : mj_name2id(model.get(), mjOBJ_BODY, task.forward_body.c_str());
  if (!task.forward_body.empty() && body < 0) {
    return absl::InvalidArgumentError(absl::StrCat(
        task.name, ": the model has no body named '", task.forward_body, "'"));
  }
  if (task.observe_qpos_from > model->nq) {
    return absl::InvalidArgumentError(
        absl::StrCat(task.name, ": cannot skip ", task.observe_qpos_from,
                     " of ", model->nq, " qpos entries"));
  }
  if (task.angle_index >= model->nq) {
    return absl::InvalidArgumentError(absl::StrCat(
        task.name, ": angle index ", task.angle_index, " is past qpos"));
  }
  absl::StatusOr<MjDataPtr> data = MakeData(model.get());
  if (!data.ok()) return data.status();
  EnvSpec spec;
  spec.name = task.name;
  if (task.subtree_com && body < 0) {
    return absl::InvalidArgumentError(
        absl::StrCat(task.name, ": subtree_com needs a forward body"));
  }
  spec.observation_size = model->nq - task.observe_qpos_from +
                          (task.hide_velocities ? 0 : model->nv) +
                          (task.subtree_com ? 3 : 0);
  spec.max_episode_steps = task.max_episode_steps;
  return std::unique_ptr<Environment>(new LocomotionEnv(
      task, std::move(spec), std::move(model), std::move(*data), body));
}

}  // namespace vantage
