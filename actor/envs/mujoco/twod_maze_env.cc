#include "actor/envs/mujoco/twod_maze_env.h"

#include <cmath>
#include <utility>

#include "actor/envs/mujoco/models.h"
#include "actor/envs/mujoco/mujoco_env.h"

namespace vantage {
namespace {

constexpr double kTargetX = 0.15;
constexpr double kTargetY = -0.15;

class TwoDMaze : public MujocoEnv {
 public:
  TwoDMaze(EnvSpec spec, MjModelPtr model, MjDataPtr data, int particle)
      : MujocoEnv(std::move(spec), std::move(model), std::move(data),
                  /*frame_skip=*/2),
        particle_(particle) {}

 protected:
  void ResetState(std::mt19937_64& rng) override {
    PerturbState(rng, 0.01, /*normal_qvel=*/false);
  }

  StepResult Evaluate(absl::Span<const double>) override {
    const double x = data()->xpos[3 * particle_];
    const double y = data()->xpos[3 * particle_ + 1];
    StepResult result;
    result.reward =
        x > 0.0 && y < -0.08
            ? -5.0 * (std::abs(x - kTargetX) + std::abs(y - kTargetY))
            : -1.0;
    return result;
  }

  void Observe(double* observation) const override {
    observation[0] = data()->xpos[3 * particle_];
    observation[1] = data()->xpos[3 * particle_ + 1];
  }

 private:
  const int particle_;
};

}  // namespace

absl::StatusOr<std::unique_ptr<Environment>> MakeTwoDMaze() {
  absl::StatusOr<LoadedModel> loaded =
      LoadModelAndData("TwoDMaze", kTwoDMazeXml);
  if (!loaded.ok()) return loaded.status();
  const int particle = mj_name2id(loaded->model.get(), mjOBJ_BODY, "particle");
  EnvSpec spec;
  spec.name = "TwoDMaze";
  spec.observation_size = 2;
  spec.max_episode_steps = 200;
  return std::unique_ptr<Environment>(
      new TwoDMaze(std::move(spec), std::move(loaded->model),
                   std::move(loaded->data), particle));
}

}  // namespace vantage
