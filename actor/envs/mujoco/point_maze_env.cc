#include "actor/envs/mujoco/point_maze_env.h"

#include <cmath>
#include <utility>

#include "actor/envs/mujoco/models.h"
#include "actor/envs/mujoco/mujoco_env.h"

namespace vantage {
namespace {

constexpr double kGoalX = -1.5;
constexpr double kGoalY = 1.5;
constexpr double kGoalRadius = 0.3;

class PointMaze : public MujocoEnv {
 public:
  PointMaze(EnvSpec spec, MjModelPtr model, MjDataPtr data, int point)
      : MujocoEnv(std::move(spec), std::move(model), std::move(data),
                  /*frame_skip=*/5),
        point_(point) {}

 protected:
  void ResetState(std::mt19937_64& rng) override {
    PerturbState(rng, 0.1, /*normal_qvel=*/false);
  }

  StepResult Evaluate(absl::Span<const double>) override {
    const double dx = data()->xpos[3 * point_] - kGoalX;
    const double dy = data()->xpos[3 * point_ + 1] - kGoalY;
    StepResult result;
    result.terminated = std::hypot(dx, dy) < kGoalRadius;
    result.reward = result.terminated ? 1.0 : 0.0;
    return result;
  }

  void Observe(double* observation) const override {
    observation[0] = data()->xpos[3 * point_];
    observation[1] = data()->xpos[3 * point_ + 1];
    observation[2] = data()->qvel[0];
    observation[3] = data()->qvel[1];
  }

 private:
  const int point_;
};

}  // namespace

absl::StatusOr<std::unique_ptr<Environment>> MakePointMaze() {
  absl::StatusOr<LoadedModel> loaded =
      LoadModelAndData("PointMaze", kPointMazeXml);
  if (!loaded.ok()) return loaded.status();
  const int point = mj_name2id(loaded->model.get(), mjOBJ_BODY, "point");
  EnvSpec spec;
  spec.name = "PointMaze";
  spec.observation_size = 4;
  spec.max_episode_steps = 500;
  return std::unique_ptr<Environment>(
      new PointMaze(std::move(spec), std::move(loaded->model),
                    std::move(loaded->data), point));
}

}  // namespace vantage
