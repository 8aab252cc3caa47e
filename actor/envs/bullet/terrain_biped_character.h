#ifndef VANTAGE_ACTOR_ENVS_BULLET_TERRAIN_BIPED_CHARACTER_H_
#define VANTAGE_ACTOR_ENVS_BULLET_TERRAIN_BIPED_CHARACTER_H_

// The planar biped of the Terrain RL simulator's biped walking tasks
// (UBCMOCCA/TerrainRLSim: data/characters/biped2D_full.txt) and the walking
// clip its reward imitates (data/motions/biped2D_full_walk.txt), as data,
// with the planar forward kinematics both need. Coordinates are the
// simulator's plane: x forward, y up; an angle turns +x towards +y.

#include <array>

namespace vantage {

inline constexpr int kTerrainBipedJoints = 11;
inline constexpr int kTerrainBipedBodies = kTerrainBipedJoints + 1;

// Body i hangs from joint i (body 0, the torso, from the root). Each body
// is a box.
struct TerrainBipedBody {
  const char* name;
  double mass;    // kg
  double width;   // full size along the joint frame's x (m)
  double height;  // full size along its y (m)
  // The box centre in its joint's frame.
  double centre_x;
  double centre_y;
  // Touching the ground with this body is a fall.
  bool fall_contact;
};

// Joint j (1..11) joins body j to body `parent`; index 0 is the root.
struct TerrainBipedJoint {
  const char* name;
  int parent;
  // The joint's position in its parent joint's frame (m).
  double attach_x;
  double attach_y;
  double lower;  // limits (rad)
  double upper;
  double torque_limit;  // N m
  double kp;            // PD gains (N m / rad, N m s / rad)
  double kd;
  double diff_weight;  // the joint's weight in the imitation errors
};

const std::array<TerrainBipedBody, kTerrainBipedBodies>& TerrainBipedBodyDefs();
// Index 0 is the root (no limits, no gains; its diff weight is the root
// rotation's).
const std::array<TerrainBipedJoint, kTerrainBipedBodies>&
TerrainBipedJointDefs();

// The root joint's position and rotation and the 11 joint angles (joint
// order: right hip, knee, ankle, left hip, knee, ankle, right shoulder,
// elbow, left shoulder, elbow, neck).
struct TerrainBipedPose {
  double root_x = 0.0;
  double root_y = 0.0;
  double root_angle = 0.0;
  std::array<double, kTerrainBipedJoints> joints = {};
};

// Where every body's box is in the plane.
struct BoxPlacement {
  double x = 0.0;  // centre
  double y = 0.0;
  double angle = 0.0;
};
std::array<BoxPlacement, kTerrainBipedBodies> PlaceBodies(
    const TerrainBipedPose& pose);

// A body's centre velocity and angular velocity when the pose changes at
// `rates` (each field the time derivative of the pose's).
struct BoxMotion {
  double vx = 0.0;
  double vy = 0.0;
  double omega = 0.0;
};
std::array<BoxMotion, kTerrainBipedBodies> MoveBodies(
    const TerrainBipedPose& pose, const TerrainBipedPose& rates);
// The lowest corner of body `body`'s box, placed as `placement`.
double LowestCorner(int body, const BoxPlacement& placement);
// Where joint `joint` (1..11) is.
std::array<double, 2> JointPosition(const TerrainBipedPose& pose, int joint);

// The walking clip: 11 key poses 0.1 s apart (the last is the first a
// stride later), looped. The clip's cycle is 1 s.
inline constexpr double kWalkCycleSeconds = 1.0;
// How far the root advances per cycle (m).
double WalkCycleAdvance();
// The pose at `time` seconds (any time >= 0: each later cycle advances the
// root by WalkCycleAdvance()), keyframes interpolated linearly.
TerrainBipedPose WalkPose(double time);
// Its rate of change at `time`: the central difference over 1/60 s.
TerrainBipedPose WalkPoseRate(double time);

}  // namespace vantage

#endif  // VANTAGE_ACTOR_ENVS_BULLET_TERRAIN_BIPED_CHARACTER_H_
