#ifndef VANTAGE_ACTOR_ENVS_MUJOCO_GYM_TASKS_H_
#define VANTAGE_ACTOR_ENVS_MUJOCO_GYM_TASKS_H_

#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "actor/envs/env_options.h"
#include "common/env/environment.h"

namespace vantage {

// The Gymnasium v4 locomotion tasks with their rules (see gym_tasks.cc):
// HalfCheetah, Hopper, Walker2d and Ant, and two variants of HalfCheetah:
// SparseHalfCheetah, its dynamics with the sparse reward of the VIME and
// EX2 papers (1 per step while the torso is more than 5 m ahead of the
// start, else 0), and Ex2SparseHalfCheetah, the one EX2's experiments ran
// (envs/half_cheetah_env.py of jcoreyes/ex2 over rllab's HalfCheetahEnv):
// the same model stepped at rllab's dt of 0.01 s (frame skip 1), 500 steps;
// reward 1 while the torso's subtree centre of mass is more than 5 m from
// the start either way, else 0; observation qpos[1:], qvel and that centre
// (20); reset noise N(0, 0.01^2) on qpos and N(0, 0.1^2) on qvel.
std::vector<std::string> GymTaskNames();

// One of GymTaskNames() with options over its defaults (the spec is named
// name.Canonical()); an unknown option or a bad value is InvalidArgument.
absl::StatusOr<std::unique_ptr<Environment>> MakeGymTask(const EnvName& name);

// The options a gym task takes, with its defaults.
std::vector<EnvOptionInfo> GymTaskOptions(const std::string& name);

// Any MJCF file: observation (qpos, qvel), actions all actuators clipped to
// their ctrlrange, the task read from the model's <custom> block (README,
// "Bring your own MJCF").
absl::StatusOr<std::unique_ptr<Environment>> MakeMjcfEnv(
    const std::string& path);

}  // namespace vantage

#endif  // VANTAGE_ACTOR_ENVS_MUJOCO_GYM_TASKS_H_
