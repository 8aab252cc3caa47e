#ifndef VANTAGE_ACTOR_ENVS_MUJOCO_TWOD_MAZE_ENV_H_
#define VANTAGE_ACTOR_ENVS_MUJOCO_TWOD_MAZE_ENV_H_

#include <memory>

#include "absl/status/statusor.h"
#include "common/env/environment.h"

namespace vantage {

// The 2D maze of EX2's experiments (Ex2TwoDMaze-v0 of jcoreyes/ex2:
// envs/twod_maze.py, envs/assets/twod_maze.xml), which the paper's maze
// results ran on: a point mass (radius 0.03, density 1000, damping 1,
// timestep 0.01, Euler, frame skip 2) in a 0.6 m square split from below
// by a wall from (0, -0.3) to (0, 0.05); it starts at (-0.15, -0.15)
// (+-0.01 noise on position and velocity), the target is (0.15, -0.15) on
// the other side. Observation (x, y); reward -5 x (L1 distance to the
// target) inside the pocket x > 0, y < -0.08, and -1 everywhere else; no
// termination, 200 steps per episode. Actions in [-1, 1] become forces of
// half that (the reference's normalised action space over motors limited
// to [-0.5, 0.5]).
absl::StatusOr<std::unique_ptr<Environment>> MakeTwoDMaze();

}  // namespace vantage

#endif  // VANTAGE_ACTOR_ENVS_MUJOCO_TWOD_MAZE_ENV_H_
