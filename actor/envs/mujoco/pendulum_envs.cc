#include "actor/envs/mujoco/pendulum_envs.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "actor/envs/mujoco/models.h"
#include "actor/envs/mujoco/mujoco_env.h"

namespace vantage {
namespace {

struct InvertedPendulumTask {
  bool hide_velocities = false;
};

std::vector<EnvOption> Options(InvertedPendulumTask& task) {
  return {{"hide_velocities",
           "observe the cart's and the pole's positions only (partially "
           "observable: velocities must be inferred over time)",
           &task.hide_velocities}};
}

class InvertedPendulum : public MujocoEnv {
 public:
  InvertedPendulum(EnvSpec spec, MjModelPtr model, MjDataPtr data,
                   bool hide_velocities)
      : MujocoEnv(std::move(spec), std::move(model), std::move(data),
                  /*frame_skip=*/2),
        hide_velocities_(hide_velocities) {}

 protected:
  void ResetState(std::mt19937_64& rng) override {
    PerturbState(rng, 0.01, /*normal_qvel=*/false);
  }
  StepResult Evaluate(absl::Span<const double>) override {
    StepResult result;
    result.reward = 1.0;
    const double angle = data()->qpos[1];
    bool finite = true;
    for (int i = 0; i < model()->nq; ++i)
      finite &= std::isfinite(data()->qpos[i]);
    for (int i = 0; i < model()->nv; ++i)
      finite &= std::isfinite(data()->qvel[i]);
    result.terminated = !finite || std::fabs(angle) > 0.2;
    return result;
  }
  void Observe(double* observation) const override {
    std::copy(data()->qpos, data()->qpos + 2, observation);
    if (!hide_velocities_) {
      std::copy(data()->qvel, data()->qvel + 2, observation + 2);
    }
  }

 private:
  const bool hide_velocities_;
};

class InvertedDoublePendulum : public MujocoEnv {
 public:
  InvertedDoublePendulum(EnvSpec spec, MjModelPtr model, MjDataPtr data,
                         int tip)
      : MujocoEnv(std::move(spec), std::move(model), std::move(data),
                  /*frame_skip=*/5),
        tip_(tip) {}

 protected:
  void ResetState(std::mt19937_64& rng) override {
    PerturbState(rng, 0.1, /*normal_qvel=*/true);
  }
  StepResult Evaluate(absl::Span<const double>) override {
    const mjData* d = data();
    const double x = d->site_xpos[3 * tip_];
    const double y = d->site_xpos[3 * tip_ + 2];
    const double w1 = d->qvel[1];
    const double w2 = d->qvel[2];
    StepResult result;
    result.reward = 10.0 - (0.01 * x * x + (y - 2.0) * (y - 2.0)) -
                    (1e-3 * w1 * w1 + 5e-3 * w2 * w2);
    result.terminated = y <= 1.0;
    return result;
  }
  void Observe(double* observation) const override {
    const mjData* d = data();
    double* out = observation;
    *out++ = d->qpos[0];
    for (int i = 1; i < 3; ++i) *out++ = std::sin(d->qpos[i]);
    for (int i = 1; i < 3; ++i) *out++ = std::cos(d->qpos[i]);
    for (int i = 0; i < 3; ++i) *out++ = std::clamp(d->qvel[i], -10.0, 10.0);
    for (int i = 0; i < 3; ++i) {
      *out++ = std::clamp(d->qfrc_constraint[i], -10.0, 10.0);
    }
  }

 private:
  const int tip_;
};

template <typename Env, typename... Args>
absl::StatusOr<std::unique_ptr<Environment>> Build(const char* name,
                                                   const char* xml,
                                                   int64_t observation_size,
                                                   Args... args) {
  absl::StatusOr<LoadedModel> loaded = LoadModelAndData(name, xml);
  if (!loaded.ok()) return loaded.status();
  EnvSpec spec;
  spec.name = name;
  spec.observation_size = observation_size;
  spec.max_episode_steps = 1000;
  return std::unique_ptr<Environment>(
      new Env(std::move(spec), std::move(loaded->model),
              std::move(loaded->data), args...));
}

}  // namespace

absl::StatusOr<std::unique_ptr<Environment>> MakeInvertedPendulum(
    const EnvName& name) {
  InvertedPendulumTask task;
  if (absl::Status status =
          ApplyEnvOptions(name.task, Options(task), name.options);
      !status.ok()) {
    return status;
  }
  const std::string canonical = name.Canonical();
  return Build<InvertedPendulum>(canonical.c_str(), kInvertedPendulumXml,
                                 task.hide_velocities ? 2 : 4,
                                 task.hide_velocities);
}

std::vector<EnvOptionInfo> InvertedPendulumOptions() {
  InvertedPendulumTask task;
  return Describe(Options(task));
}

absl::StatusOr<std::unique_ptr<Environment>> MakeInvertedDoublePendulum() {
  // The tip site is the model's only site.
  return Build<InvertedDoublePendulum>("InvertedDoublePendulum",
                                       kInvertedDoublePendulumXml, 11, 0);
}

}  // namespace vantage
