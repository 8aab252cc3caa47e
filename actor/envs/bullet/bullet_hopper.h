#ifndef VANTAGE_ACTOR_ENVS_BULLET_BULLET_HOPPER_H_
#define VANTAGE_ACTOR_ENVS_BULLET_BULLET_HOPPER_H_

#include <memory>

#include "absl/status/statusor.h"
#include "common/env/environment.h"

namespace vantage {

// Gymnasium's Hopper-v4 on Bullet: the hopper.xml geometry (torso, thigh,
// leg, foot capsules, density 1000), 3 hinges with gear 200, joint damping
// 1 and armature 1 (added to the link inertia: Bullet has no rotor
// inertia), timestep 0.002 s x frame skip 4. Observation 11: qpos[1:]
// (z, pitch, 3 hinges) and qvel clipped to +-10; reward forward velocity +
// 1 - 1e-3 |a|^2; terminated unless z > 0.7, |pitch| < 0.2 and every
// qpos[2:], qvel entry is within +-100; reset noise U(+-5e-3).
absl::StatusOr<std::unique_ptr<Environment>> MakeBulletHopper();

}  // namespace vantage

#endif  // VANTAGE_ACTOR_ENVS_BULLET_BULLET_HOPPER_H_
