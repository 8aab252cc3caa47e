#ifndef VANTAGE_ACTOR_ENVS_MUJOCO_PENDULUM_ENVS_H_
#define VANTAGE_ACTOR_ENVS_MUJOCO_PENDULUM_ENVS_H_

#include <memory>

#include "absl/status/statusor.h"
#include "actor/envs/env_options.h"
#include "common/env/environment.h"

namespace vantage {

// Gymnasium v4 InvertedPendulum: obs (qpos, qvel) = 4, reward 1 per step,
// terminated once |pole angle| > 0.2 rad; frame skip 2 (dt 0.04 s).
// Option hide_velocities (`InvertedPendulum:hide_velocities=true`): obs
// qpos only (2), a standard partially observable variant.
absl::StatusOr<std::unique_ptr<Environment>> MakeInvertedPendulum(
    const EnvName& name);
std::vector<EnvOptionInfo> InvertedPendulumOptions();

// Gymnasium v4 InvertedDoublePendulum: obs 11 = (cart x, sin and cos of
// both hinges, clip(qvel, +-10), clip(qfrc_constraint, +-10)), reward
// 10 - 0.01 x_tip^2 - (y_tip - 2)^2 - 1e-3 w1^2 - 5e-3 w2^2, terminated once
// the tip is at or below y = 1; frame skip 5 (dt 0.05 s).
absl::StatusOr<std::unique_ptr<Environment>> MakeInvertedDoublePendulum();

}  // namespace vantage

#endif  // VANTAGE_ACTOR_ENVS_MUJOCO_PENDULUM_ENVS_H_
