#include "actor/envs/mujoco/humanoid_env.h"

#include <algorithm>
#include <string>
#include <utility>

#include "absl/strings/str_cat.h"
#include "actor/envs/mujoco/models.h"
#include "actor/envs/mujoco/mujoco_env.h"

namespace vantage {
namespace {

class Humanoid : public MujocoEnv {
 public:
  Humanoid(EnvSpec spec, MjModelPtr model, MjDataPtr data)
      : MujocoEnv(std::move(spec), std::move(model), std::move(data),
                  /*frame_skip=*/5) {}

 protected:
  void ResetState(std::mt19937_64& rng) override {
    PerturbState(rng, 1e-2, /*normal_qvel=*/false);
  }

  void BeforeStep() override { x_before_ = MassCenterX(); }

  // The torso, the root of the free joint.
  int TrackedBody() const override { return 1; }

  StepResult Evaluate(absl::Span<const double> action) override {
    // cvel and cfrc_ext of the final state, as Gymnasium's v4 computes them.
    mj_rnePostConstraint(model(), mutable_data());
    const double velocity = (MassCenterX() - x_before_) / spec().control_dt;
    double effort = 0.0;
    for (double a : action) effort += a * a;
    const double z = data()->qpos[2];
    StepResult result;
    result.terminated = !(z > 1.0 && z < 2.0);
    result.reward = 1.25 * velocity + 5.0 - 0.1 * effort;
    return result;
  }

  void Observe(double* observation) const override {
    const mjModel* m = model();
    const mjData* d = data();
    double* out = std::copy(d->qpos + 2, d->qpos + m->nq, observation);
    out = std::copy(d->qvel, d->qvel + m->nv, out);
    out = std::copy(d->cinert, d->cinert + 10 * m->nbody, out);
    out = std::copy(d->cvel, d->cvel + 6 * m->nbody, out);
    out = std::copy(d->qfrc_actuator, d->qfrc_actuator + m->nv, out);
    std::copy(d->cfrc_ext, d->cfrc_ext + 6 * m->nbody, out);
  }

 private:
  double MassCenterX() const {
    const mjModel* m = model();
    double weighted = 0.0;
    double mass = 0.0;
    for (int b = 0; b < m->nbody; ++b) {
      weighted += m->body_mass[b] * data()->xipos[3 * b];
      mass += m->body_mass[b];
    }
    return weighted / mass;
  }

  double x_before_ = 0.0;
};

}  // namespace

absl::StatusOr<std::unique_ptr<Environment>> MakeHumanoid() {
  absl::StatusOr<LoadedModel> loaded =
      LoadModelAndData("Humanoid", kHumanoidXml);
  if (!loaded.ok()) return loaded.status();
  const mjModel* m = loaded->model.get();
  EnvSpec spec;
  spec.name = "Humanoid";
  spec.observation_size =
      (m->nq - 2) + m->nv + 10 * m->nbody + 6 * m->nbody + m->nv + 6 * m->nbody;
  spec.max_episode_steps = 1000;
  return std::unique_ptr<Environment>(new Humanoid(
      std::move(spec), std::move(loaded->model), std::move(loaded->data)));
}

}  // namespace vantage
