#ifndef VANTAGE_ACTOR_ENVS_MUJOCO_GYM_TASKS_H_
#define VANTAGE_ACTOR_ENVS_MUJOCO_GYM_TASKS_H_

#include <memory>
#include <string>

#include "absl/status/statusor.h"
#include "common/env/environment.h"

namespace vantage {

// The Gymnasium v4 locomotion tasks with their rules (see gym_tasks.cc).
absl::StatusOr<std::unique_ptr<Environment>> MakeHalfCheetah();
absl::StatusOr<std::unique_ptr<Environment>> MakeHopper();
absl::StatusOr<std::unique_ptr<Environment>> MakeWalker2d();
absl::StatusOr<std::unique_ptr<Environment>> MakeAnt();

// HalfCheetah dynamics with the sparse reward of the VIME and EX2 papers:
// 1 per step while the torso is more than 5 m ahead of the start, else 0.
absl::StatusOr<std::unique_ptr<Environment>> MakeSparseHalfCheetah();

// Any MJCF file: observation (qpos, qvel), actions all actuators clipped to
// their ctrlrange, the task read from the model's <custom> block (README,
// "Bring your own MJCF").
absl::StatusOr<std::unique_ptr<Environment>> MakeMjcfEnv(
    const std::string& path);

}  // namespace vantage

#endif  // VANTAGE_ACTOR_ENVS_MUJOCO_GYM_TASKS_H_
