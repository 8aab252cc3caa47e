#ifndef VANTAGE_ACTOR_ENVS_MUJOCO_HUMANOID_ENV_H_
#define VANTAGE_ACTOR_ENVS_MUJOCO_HUMANOID_ENV_H_

#include <memory>

#include "absl/status/statusor.h"
#include "common/env/environment.h"

namespace vantage {

// Gymnasium v4 Humanoid: obs 376 = qpos[2:] (22), qvel (23), cinert (14 x
// 10), cvel (14 x 6), qfrc_actuator (23), cfrc_ext (14 x 6), world body
// included; reward 1.25 * x-velocity of the centre of mass + 5 (healthy) -
// 0.1 |a|^2 (v4 leaves the contact cost out); terminated once the torso
// height leaves (1.0, 2.0); frame skip 5 (dt 0.015 s); reset noise
// U(-0.01, 0.01) on qpos and qvel.
absl::StatusOr<std::unique_ptr<Environment>> MakeHumanoid();

}  // namespace vantage

#endif  // VANTAGE_ACTOR_ENVS_MUJOCO_HUMANOID_ENV_H_
