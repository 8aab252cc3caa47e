#include "actor/envs/bullet/terrain_biped_character.h"

#include <algorithm>
#include <cmath>

namespace vantage {
namespace {

constexpr int kRoot = 0;

// One key pose of the clip: root x and y, then the joint angles (the
// clip's root never turns: its quaternions are all the identity).
struct KeyPose {
  double root_x;
  double root_y;
  std::array<double, kTerrainBipedJoints> joints;
};

constexpr double kKeyInterval = 0.1;  // seconds between key poses
constexpr std::array<KeyPose, 11> kWalkClip = {{
    {0.0,
     0.75205,
     {0.48394, -0.23542, -0.00088, -0.35258, -0.40699, 0.1, -0.35, 0.05, 0.2,
      0.2, 0.0}},
    {0.10268,
     0.7463,
     {0.52656, -0.54109, 0.01454, -0.05648, -1.10964, 0.10315, -0.25, 0.05,
      0.35, 0.3, 0.0}},
    {0.25712,
     0.78573,
     {0.16935, -0.28059, 0.11124, 0.16935, -1.26539, 0.09289, -0.2, 0.05, 0.2,
      0.4, 0.0}},
    {0.38363,
     0.78368,
     {-0.06757, -0.13631, 0.21388, 0.88898, -1.54178, 0.22671, -0.1, 0.05, 0.1,
      0.35, 0.0}},
    {0.5241,
     0.7463,
     {-0.24329, -0.19277, 0.43606, 0.69399, -0.66751, 0.09062, 0.0, 0.1, 0.0,
      0.2, 0.0}},
    {0.76766,
     0.75205,
     {-0.35258, -0.40699, 0.1, 0.48394, -0.23542, 0.00088, 0.2, 0.2, -0.15, 0.1,
      0.0}},
    {0.87034,
     0.7463,
     {-0.05648, -1.10964, 0.10315, 0.52656, -0.54109, 0.01454, 0.35, 0.3, -0.35,
      0.05, 0.0}},
    {1.02478,
     0.78573,
     {0.16935, -1.26539, 0.09289, 0.16935, -0.28059, 0.11124, 0.2, 0.4, -0.25,
      0.05, 0.0}},
    {1.15129,
     0.78368,
     {0.88898, -1.54178, 0.22671, -0.06757, -0.13631, 0.21388, 0.1, 0.35, -0.2,
      0.05, 0.0}},
    {1.29176,
     0.7463,
     {0.69399, -0.66751, 0.09062, -0.24329, -0.19277, 0.43606, 0.0, 0.2, -0.1,
      0.05, 0.0}},
    {1.53532,
     0.75205,
     {0.48394, -0.23542, 0.00088, -0.35258, -0.40699, 0.1, -0.15, 0.1, 0.0, 0.1,
      0.0}},
}};

std::array<double, 2> Rotate(double angle, double x, double y) {
  const double c = std::cos(angle);
  const double s = std::sin(angle);
  return {c * x - s * y, s * x + c * y};
}

// Every joint frame's position and angle in the plane (index 0: the root).
struct Frames {
  std::array<double, kTerrainBipedBodies> x;
  std::array<double, kTerrainBipedBodies> y;
  std::array<double, kTerrainBipedBodies> angle;
};

Frames JointFrames(const TerrainBipedPose& pose) {
  const auto& joints = TerrainBipedJointDefs();
  Frames frames;
  frames.x[kRoot] = pose.root_x;
  frames.y[kRoot] = pose.root_y;
  frames.angle[kRoot] = pose.root_angle;
  // Parents come before their children.
  for (int j = 1; j < kTerrainBipedBodies; ++j) {
    const TerrainBipedJoint& joint = joints[j];
    const int p = joint.parent;
    const auto offset = Rotate(frames.angle[p], joint.attach_x, joint.attach_y);
    frames.x[j] = frames.x[p] + offset[0];
    frames.y[j] = frames.y[p] + offset[1];
    frames.angle[j] = frames.angle[p] + pose.joints[j - 1];
  }
  return frames;
}

}  // namespace

const std::array<TerrainBipedBody, kTerrainBipedBodies>&
TerrainBipedBodyDefs() {
  static const std::array<TerrainBipedBody, kTerrainBipedBodies> bodies = {{
      {"torso", 25.0, 0.1, 0.45, 0.0, 0.19, true},
      {"right_thigh", 5.0, 0.0846, 0.4, 0.0, -0.1745, true},
      {"right_shin", 2.5, 0.065, 0.416, 0.0, -0.183, false},
      {"right_foot", 0.5, 0.177, 0.05, 0.0518, -0.0224, false},
      {"left_thigh", 5.0, 0.0846, 0.4, 0.0, -0.1745, true},
      {"left_shin", 2.5, 0.065, 0.416, 0.0, -0.183, false},
      {"left_foot", 0.5, 0.177, 0.05, 0.0518, -0.0224, false},
      {"right_upper_arm", 1.5, 0.07, 0.325, 0.0, -0.1545, true},
      {"right_forearm", 0.75, 0.0546, 0.3, 0.0, -0.145, true},
      {"left_upper_arm", 1.5, 0.07, 0.325, 0.0, -0.1545, true},
      {"left_forearm", 0.75, 0.0546, 0.3, 0.0, -0.145, true},
      {"head", 3.5, 0.1, 0.15, 0.02, 0.1, true},
  }};
  return bodies;
}

const std::array<TerrainBipedJoint, kTerrainBipedBodies>&
TerrainBipedJointDefs() {
  static const std::array<TerrainBipedJoint, kTerrainBipedBodies> joints = {{
      {"root", -1, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0},
      {"right_hip", 0, 0.0, 0.0, -0.5, 2.57, 150.0, 200.0, 20.0, 0.3},
      {"right_knee", 1, 0.0, -0.352, -3.0, 0.0, 125.0, 200.0, 20.0, 0.3},
      {"right_ankle", 2, 0.0, -0.391, -1.57, 1.57, 100.0, 100.0, 10.0, 0.2},
      {"left_hip", 0, 0.0, 0.0, -0.5, 2.57, 150.0, 200.0, 20.0, 0.3},
      {"left_knee", 4, 0.0, -0.352, -3.0, 0.0, 125.0, 200.0, 20.0, 0.3},
      {"left_ankle", 5, 0.0, -0.391, -1.57, 1.57, 100.0, 100.0, 10.0, 0.2},
      {"right_shoulder", 0, 0.0, 0.41, -1.2, 3.0, 100.0, 150.0, 15.0, 0.3},
      {"right_elbow", 7, 0.0, -0.31, 0.0, 2.8, 75.0, 100.0, 10.0, 0.3},
      {"left_shoulder", 0, 0.0, 0.41, -1.2, 3.0, 100.0, 150.0, 15.0, 0.3},
      {"left_elbow", 9, 0.0, -0.31, 0.0, 2.8, 75.0, 100.0, 10.0, 0.3},
      {"neck", 0, -0.02, 0.42, -0.57, 0.57, 50.0, 100.0, 10.0, 0.3},
  }};
  return joints;
}

std::array<BoxPlacement, kTerrainBipedBodies> PlaceBodies(
    const TerrainBipedPose& pose) {
  const auto& bodies = TerrainBipedBodyDefs();
  const Frames frames = JointFrames(pose);
  std::array<BoxPlacement, kTerrainBipedBodies> placements;
  for (int b = 0; b < kTerrainBipedBodies; ++b) {
    const auto centre =
        Rotate(frames.angle[b], bodies[b].centre_x, bodies[b].centre_y);
    placements[b] = {frames.x[b] + centre[0], frames.y[b] + centre[1],
                     frames.angle[b]};
  }
  return placements;
}

std::array<BoxMotion, kTerrainBipedBodies> MoveBodies(
    const TerrainBipedPose& pose, const TerrainBipedPose& rates) {
  const auto& joints = TerrainBipedJointDefs();
  const auto& bodies = TerrainBipedBodyDefs();
  const Frames frames = JointFrames(pose);
  // Each joint frame's velocity and angular velocity, root first; in the
  // plane, omega x r = omega * (-r_y, r_x).
  std::array<BoxMotion, kTerrainBipedBodies> joint_motion;
  joint_motion[kRoot] = {rates.root_x, rates.root_y, rates.root_angle};
  for (int j = 1; j < kTerrainBipedBodies; ++j) {
    const int p = joints[j].parent;
    const double rx = frames.x[j] - frames.x[p];
    const double ry = frames.y[j] - frames.y[p];
    const BoxMotion& parent = joint_motion[p];
    joint_motion[j] = {parent.vx - parent.omega * ry,
                       parent.vy + parent.omega * rx,
                       parent.omega + rates.joints[j - 1]};
  }
  std::array<BoxMotion, kTerrainBipedBodies> motions;
  for (int b = 0; b < kTerrainBipedBodies; ++b) {
    const auto r =
        Rotate(frames.angle[b], bodies[b].centre_x, bodies[b].centre_y);
    const BoxMotion& joint = joint_motion[b];
    motions[b] = {joint.vx - joint.omega * r[1], joint.vy + joint.omega * r[0],
                  joint.omega};
  }
  return motions;
}

double LowestCorner(int body, const BoxPlacement& placement) {
  const TerrainBipedBody& box = TerrainBipedBodyDefs()[body];
  double lowest = placement.y;
  for (double sx : {-0.5, 0.5}) {
    for (double sy : {-0.5, 0.5}) {
      const auto corner =
          Rotate(placement.angle, sx * box.width, sy * box.height);
      lowest = std::min(lowest, placement.y + corner[1]);
    }
  }
  return lowest;
}

std::array<double, 2> JointPosition(const TerrainBipedPose& pose, int joint) {
  const Frames frames = JointFrames(pose);
  return {frames.x[joint], frames.y[joint]};
}

double WalkCycleAdvance() {
  return kWalkClip.back().root_x - kWalkClip.front().root_x;
}

TerrainBipedPose WalkPose(double time) {
  const double cycles = std::floor(std::max(time, 0.0) / kWalkCycleSeconds);
  const double within = std::max(time, 0.0) - cycles * kWalkCycleSeconds;
  const int last = static_cast<int>(kWalkClip.size()) - 1;
  const int key = std::min(last - 1, static_cast<int>(within / kKeyInterval));
  const double blend =
      std::clamp((within - key * kKeyInterval) / kKeyInterval, 0.0, 1.0);
  const KeyPose& a = kWalkClip[key];
  const KeyPose& b = kWalkClip[key + 1];
  TerrainBipedPose pose;
  pose.root_x =
      a.root_x + blend * (b.root_x - a.root_x) + cycles * WalkCycleAdvance();
  pose.root_y = a.root_y + blend * (b.root_y - a.root_y);
  for (int j = 0; j < kTerrainBipedJoints; ++j) {
    pose.joints[j] = a.joints[j] + blend * (b.joints[j] - a.joints[j]);
  }
  return pose;
}

TerrainBipedPose WalkPoseRate(double time) {
  constexpr double kHalf = 1.0 / 120.0;
  const double from = std::max(0.0, time - kHalf);
  const double to = from + 2 * kHalf;
  const TerrainBipedPose a = WalkPose(from);
  const TerrainBipedPose b = WalkPose(to);
  const double scale = 1.0 / (to - from);
  TerrainBipedPose rate;
  rate.root_x = (b.root_x - a.root_x) * scale;
  rate.root_y = (b.root_y - a.root_y) * scale;
  rate.root_angle = (b.root_angle - a.root_angle) * scale;
  for (int j = 0; j < kTerrainBipedJoints; ++j) {
    rate.joints[j] = (b.joints[j] - a.joints[j]) * scale;
  }
  return rate;
}

}  // namespace vantage
