#include "actor/envs/mujoco/mujoco_env.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "absl/strings/str_cat.h"

namespace vantage {

MujocoEnv::MujocoEnv(EnvSpec spec, MjModelPtr model, MjDataPtr data,
                     int frame_skip)
    : spec_(std::move(spec)),
      model_(std::move(model)),
      data_(std::move(data)),
      frame_skip_(frame_skip) {
  const mjModel* m = model_.get();
  spec_.discrete = false;
  spec_.action_size = m->nu;
  spec_.action_low.assign(m->nu, -std::numeric_limits<double>::infinity());
  spec_.action_high.assign(m->nu, std::numeric_limits<double>::infinity());
  for (int i = 0; i < m->nu; ++i) {
    if (m->actuator_ctrllimited[i]) {
      spec_.action_low[i] = m->actuator_ctrlrange[2 * i];
      spec_.action_high[i] = m->actuator_ctrlrange[2 * i + 1];
    }
  }
  spec_.control_dt = m->opt.timestep * frame_skip_;
  clipped_.resize(m->nu);
}

absl::Status MujocoEnv::Reset(uint64_t seed, absl::Span<double> observation) {
  if (observation.size() != static_cast<size_t>(spec_.observation_size)) {
    return absl::InvalidArgumentError(absl::StrCat(
        spec_.name, ": observation buffer holds ", observation.size(),
        " values, expected ", spec_.observation_size));
  }
  rng_.seed(seed);
  absl::Status status = GuardMujoco([&] {
    mj_resetData(model_.get(), data_.get());
    ResetState(rng_);
    mj_forward(model_.get(), data_.get());
  });
  if (!status.ok()) return status;
  Observe(observation.data());
  needs_reset_ = false;
  return absl::OkStatus();
}

absl::StatusOr<StepResult> MujocoEnv::Step(absl::Span<const double> action,
                                           absl::Span<double> observation) {
  if (needs_reset_) {
    return absl::FailedPreconditionError(
        absl::StrCat(spec_.name, ": Reset before stepping"));
  }
  if (absl::Status status = CheckAction(spec_, action); !status.ok()) {
    return status;
  }
  if (observation.size() != static_cast<size_t>(spec_.observation_size)) {
    return absl::InvalidArgumentError(absl::StrCat(
        spec_.name, ": observation buffer holds ", observation.size(),
        " values, expected ", spec_.observation_size));
  }
  mjData* d = data_.get();
  for (int i = 0; i < model_->nu; ++i) {
    clipped_[i] =
        std::clamp(action[i], spec_.action_low[i], spec_.action_high[i]);
    d->ctrl[i] = clipped_[i];
  }
  BeforeStep();
  for (int w : {mjWARN_BADQPOS, mjWARN_BADQVEL, mjWARN_BADQACC}) {
    d->warning[w].number = 0;
  }
  absl::Status status = GuardMujoco([&] {
    for (int i = 0; i < frame_skip_; ++i) mj_step(model_.get(), d);
    // mj_step leaves body and site positions at the start of its last
    // substep; rewards and observations read them at the end.
    mj_kinematics(model_.get(), d);
  });
  if (status.ok()) {
    for (const auto& [warning, what] :
         {std::make_pair(mjWARN_BADQPOS, "qpos"),
          std::make_pair(mjWARN_BADQVEL, "qvel"),
          std::make_pair(mjWARN_BADQACC, "qacc")}) {
      if (d->warning[warning].number > 0) {
        status = absl::InternalError(
            absl::StrCat(spec_.name, ": the simulation became unstable (bad ",
                         what, ") at t=", d->time, "s; reset the environment"));
        break;
      }
    }
  }
  if (!status.ok()) {
    needs_reset_ = true;
    return status;
  }
  const StepResult result = Evaluate(clipped_);
  Observe(observation.data());
  return result;
}

void MujocoEnv::PerturbState(std::mt19937_64& rng, double scale,
                             bool normal_qvel) {
  mjData* d = data_.get();
  std::uniform_real_distribution<double> uniform(-scale, scale);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (int i = 0; i < model_->nq; ++i) d->qpos[i] += uniform(rng);
  for (int i = 0; i < model_->nv; ++i) {
    d->qvel[i] += normal_qvel ? scale * normal(rng) : uniform(rng);
  }
}

}  // namespace vantage
