#ifndef VANTAGE_ACTOR_ENVS_MUJOCO_LOCOMOTION_ENV_H_
#define VANTAGE_ACTOR_ENVS_MUJOCO_LOCOMOTION_ENV_H_

#include <limits>
#include <memory>
#include <string>

#include "absl/status/statusor.h"
#include "actor/envs/mujoco/mujoco_env.h"

namespace vantage {

// The rules shared by forward-locomotion tasks (HalfCheetah, Hopper,
// Walker2d, Ant and user MJCF models):
//   reward = forward_weight * x-velocity of forward_body
//          + healthy_reward (while healthy, or always if unhealthiness
//            terminates) - ctrl_cost * |action|^2,
// or, with a sparse threshold, 1 per step while the forward body's x
// exceeds it and 0 otherwise. Healthy: forward body height in (min_z,
// max_z), qpos[angle_index] in (min_angle, max_angle), every entry of
// (qpos[2:], qvel) within +-state_limit, all finite.
struct LocomotionTask {
  std::string name;
  int frame_skip = 1;
  int64_t max_episode_steps = 1000;
  // Empty: no forward reward and no height rule.
  std::string forward_body = "torso";
  double forward_weight = 1.0;
  double ctrl_cost = 0.0;
  double healthy_reward = 0.0;
  bool terminate_when_unhealthy = false;
  double min_z = -std::numeric_limits<double>::infinity();
  double max_z = std::numeric_limits<double>::infinity();
  int angle_index = -1;  // -1: no angle rule
  double min_angle = 0.0;
  double max_angle = 0.0;
  double state_limit = std::numeric_limits<double>::infinity();
  // Observation = (qpos[observe_qpos_from:], clip(qvel, +-qvel_clip)).
  int observe_qpos_from = 0;
  double qvel_clip = std::numeric_limits<double>::infinity();
  // Positions only, no qvel: a partially observable task (velocities must
  // be inferred from the positions seen over time).
  bool hide_velocities = false;
  // Reset: qpos += U(-noise, noise); qvel += noise * N(0, 1) if
  // normal_qvel_noise, else U(-noise, noise).
  double reset_noise = 0.0;
  bool normal_qvel_noise = false;
  // > -inf: the sparse reward described above replaces the dense one.
  double sparse_x_threshold = -std::numeric_limits<double>::infinity();
  // The sparse reward pays beyond the threshold either way (|x| > it).
  bool sparse_either_way = false;
  // x is the forward body's subtree centre of mass (rllab's get_body_com)
  // rather than its origin, and the observation ends with that centre (3).
  bool subtree_com = false;
  // > 0: reset noise N(0, scale^2) on qpos and qvel (rllab's), instead of
  // reset_noise.
  double qpos_normal_noise = 0.0;
  double qvel_normal_noise = 0.0;
};

absl::StatusOr<std::unique_ptr<Environment>> MakeLocomotionEnv(
    const LocomotionTask& task, MjModelPtr model);

}  // namespace vantage

#endif  // VANTAGE_ACTOR_ENVS_MUJOCO_LOCOMOTION_ENV_H_
