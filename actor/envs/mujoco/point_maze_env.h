#ifndef VANTAGE_ACTOR_ENVS_MUJOCO_POINT_MAZE_ENV_H_
#define VANTAGE_ACTOR_ENVS_MUJOCO_POINT_MAZE_ENV_H_

#include <memory>

#include "absl/status/statusor.h"
#include "common/env/environment.h"

namespace vantage {

// The sparse-reward maze of the paper's first experiment: a point mass
// (force-controlled x and y, damped) in a U-maze (see kPointMazeXml).
// Observation (x, y, vx, vy); reward 1 on the step that brings the point
// within 0.3 m of the goal (-1.5, 1.5), which also terminates the episode,
// and 0 otherwise; frame skip 5 (dt 0.05 s), 500 steps per episode.
absl::StatusOr<std::unique_ptr<Environment>> MakePointMaze();

}  // namespace vantage

#endif  // VANTAGE_ACTOR_ENVS_MUJOCO_POINT_MAZE_ENV_H_
