#include "actor/envs/bullet/terrain_biped.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "absl/strings/str_cat.h"

namespace vantage {
namespace {

// The bodies' sizes across the plane (the character file's z), which only
// decide where their faces meet the ground.
constexpr std::array<double, kTerrainBipedBodies> kDepths = {
    0.278, 0.08, 0.06, 0.08, 0.08, 0.06, 0.08, 0.08, 0.08, 0.08, 0.08, 0.15};
// Character and ground both 0.9 (sim/SimCharacter.cpp, sim/Ground.cpp),
// combined by Bullet as their product; our ground's is 1.
constexpr double kFriction = 0.81;
// The ankles are the character file's end effectors.
constexpr std::array<int, 2> kEndEffectors = {3, 6};
// What a reset leaves between the lowest corner and the ground
// (ScenarioSimChar::ResolveCharGroundIntersect).
constexpr double kResetClearance = 0.001;
constexpr int kPhaseBins = 4;

PlanarModel TerrainBipedModel() {
  const auto& bodies = TerrainBipedBodyDefs();
  const auto& joints = TerrainBipedJointDefs();
  PlanarModel model;
  // Standing straight, the soles are 0.7904 m below the root joint.
  model.root_z = 0.8;
  model.timestep = TerrainBipedEnv::kPhysicsStep;
  model.gravity = 9.8;
  TerrainBipedPose zero;
  zero.root_y = model.root_z;
  const auto placements = PlaceBodies(zero);
  for (int b = 0; b < kTerrainBipedBodies; ++b) {
    PlanarLink link;
    link.name = bodies[b].name;
    link.parent = joints[b].parent;
    link.box_width = bodies[b].width;
    link.box_height = bodies[b].height;
    link.box_depth = kDepths[b];
    link.box_centre_x = placements[b].x;
    link.box_centre_z = placements[b].y;
    link.mass = bodies[b].mass;
    link.friction = kFriction;
    if (b > 0) {
      const auto at = JointPosition(zero, b);
      link.joint_x = at[0];
      link.joint_z = at[1];
      // About -y, a positive angle turns +x towards +z, as the
      // character's joints turn +x towards +y.
      link.axis = -1.0;
      link.lower = joints[b].lower;
      link.upper = joints[b].upper;
    }
    model.links.push_back(link);
  }
  return model;
}

std::vector<double> TorqueLimits() {
  std::vector<double> limits;
  for (int j = 1; j < kTerrainBipedBodies; ++j) {
    limits.push_back(TerrainBipedJointDefs()[j].torque_limit);
  }
  return limits;
}

struct CentreOfMass {
  double x = 0.0;
  double y = 0.0;
  double vx = 0.0;
  double vy = 0.0;
};

CentreOfMass CentreOf(const TerrainBipedPose& pose,
                      const TerrainBipedPose& rate) {
  const auto& bodies = TerrainBipedBodyDefs();
  const auto placed = PlaceBodies(pose);
  const auto moving = MoveBodies(pose, rate);
  CentreOfMass com;
  double mass = 0.0;
  for (int b = 0; b < kTerrainBipedBodies; ++b) {
    const double m = bodies[b].mass;
    com.x += m * placed[b].x;
    com.y += m * placed[b].y;
    com.vx += m * moving[b].vx;
    com.vy += m * moving[b].vy;
    mass += m;
  }
  com.x /= mass;
  com.y /= mass;
  com.vx /= mass;
  com.vy /= mass;
  return com;
}

}  // namespace

absl::Status TerrainBipedConfig::Validate() const {
  if (name.empty()) {
    return absl::InvalidArgumentError("terrain biped config: name is empty");
  }
  if (max_episode_steps < 1) {
    return absl::InvalidArgumentError(
        "terrain biped config: max_episode_steps must be >= 1");
  }
  if (!(stuck_distance >= 0.0) || !(stuck_seconds >= 0.0)) {
    return absl::InvalidArgumentError(
        "terrain biped config: stuck_distance and stuck_seconds must be >= 0");
  }
  return absl::OkStatus();
}

double TerrainBipedImitationReward(const TerrainBipedPose& pose,
                                   const TerrainBipedPose& rate,
                                   const TerrainBipedPose& reference,
                                   const TerrainBipedPose& reference_rate,
                                   absl::FunctionRef<double(double)> ground) {
  const auto& joints = TerrainBipedJointDefs();
  double total_weight = 0.0;
  for (const TerrainBipedJoint& joint : joints) {
    total_weight += joint.diff_weight;
  }
  const auto weight = [&](int joint) {
    return joints[joint].diff_weight / total_weight;
  };
  const auto square = [](double x) { return x * x; };
  double pose_error =
      weight(0) * square(pose.root_angle - reference.root_angle);
  double velocity_error =
      weight(0) * square(rate.root_angle - reference_rate.root_angle);
  for (int j = 0; j < kTerrainBipedJoints; ++j) {
    pose_error += weight(j + 1) * square(pose.joints[j] - reference.joints[j]);
    velocity_error +=
        weight(j + 1) * square(rate.joints[j] - reference_rate.joints[j]);
  }
  // End effectors relative to the centre of mass (x) and the ground (y).
  const CentreOfMass com = CentreOf(pose, rate);
  const CentreOfMass reference_com = CentreOf(reference, reference_rate);
  double end_error = 0.0;
  for (int joint : kEndEffectors) {
    const auto at = JointPosition(pose, joint);
    const auto reference_at = JointPosition(reference, joint);
    end_error += square((at[0] - com.x) - (reference_at[0] - reference_com.x)) +
                 square(at[1] - ground(at[0]) - reference_at[1]);
  }
  end_error /= kEndEffectors.size();
  const double root_error =
      square(pose.root_y - ground(pose.root_x) - reference.root_y);
  const double com_error = 0.1 * (square(com.vx - reference_com.vx) +
                                  square(com.vy - reference_com.vy));
  return 0.5 * std::exp(-2.0 * pose_error) +
         0.05 * std::exp(-0.005 * velocity_error) +
         0.15 * std::exp(-40.0 * end_error) +
         0.1 * std::exp(-10.0 * root_error) + 0.2 * std::exp(-10.0 * com_error);
}

absl::StatusOr<std::unique_ptr<TerrainBipedEnv>> TerrainBipedEnv::Create(
    const TerrainBipedConfig& config) {
  if (absl::Status status = config.Validate(); !status.ok()) return status;
  PlanarModel model = TerrainBipedModel();
  if (absl::Status status = ValidatePlanarModel(model); !status.ok()) {
    return status;
  }
  return std::unique_ptr<TerrainBipedEnv>(
      new TerrainBipedEnv(config, std::move(model)));
}

TerrainBipedEnv::TerrainBipedEnv(const TerrainBipedConfig& config,
                                 PlanarModel model)
    : BulletEnv(
          [&] {
            EnvSpec spec;
            spec.name = config.name;
            spec.observation_size = kObservationSize;
            spec.max_episode_steps = config.max_episode_steps;
            return spec;
          }(),
          std::move(model), TorqueLimits(), kFrameSkip),
      config_(config),
      control_dt_(kPhysicsStep * kFrameSkip),
      stuck_steps_(config.stuck_distance > 0.0 && config.stuck_seconds > 0.0
                       ? std::llround(config.stuck_seconds / control_dt_)
                       : 0) {
  // The controller's bounds (sim/CtCtrlUtil.cpp BuildBoundsPDRevolute).
  std::vector<double> low, high;
  for (int j = 1; j < kTerrainBipedBodies; ++j) {
    const TerrainBipedJoint& joint = TerrainBipedJointDefs()[j];
    const double mean = (joint.lower + joint.upper) / 2;
    const double range = joint.upper - joint.lower;
    low.push_back(mean - 2 * range);
    high.push_back(mean + 2 * range);
  }
  SetActionBounds(std::move(low), std::move(high));
}

TerrainBipedPose TerrainBipedEnv::Pose(const BulletWorld& world) const {
  TerrainBipedPose pose;
  pose.root_x = world.q(0);
  pose.root_y = world.q(1);
  pose.root_angle = -world.q(2);
  for (int j = 0; j < kTerrainBipedJoints; ++j) pose.joints[j] = world.q(3 + j);
  return pose;
}

TerrainBipedPose TerrainBipedEnv::PoseRate(const BulletWorld& world) const {
  TerrainBipedPose rate;
  rate.root_x = world.qd(0);
  rate.root_y = world.qd(1);
  rate.root_angle = -world.qd(2);
  for (int j = 0; j < kTerrainBipedJoints; ++j)
    rate.joints[j] = world.qd(3 + j);
  return rate;
}

void TerrainBipedEnv::ShapeGround(std::mt19937_64& rng, PlanarModel& model) {
  if (!config_.incline) return;
  // sim/TerrainGen2D.cpp (OverlaySlopes) with inclines.txt's
  // SlopeDeltaRange 0.1, SlopeDeltaMin 0.15 and SlopeDeltaMax 0.2: at every
  // vertex the slope moves by U(0, range), downwards with a probability
  // that pulls it into [min, max].
  constexpr double kSpacing = 0.025;  // gVertSpacing
  constexpr double kRange = 0.1, kMin = 0.15, kMax = 0.2;
  constexpr double kFrom = -2.0, kTo = 30.0, kPadEnd = 1.0;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  model.ground_start_x = kFrom;
  model.ground_spacing = kSpacing;
  model.ground_heights.clear();
  double slope = 0.0;
  double height = 0.0;
  const int vertices = static_cast<int>(std::lround((kTo - kFrom) / kSpacing));
  for (int i = 0; i <= vertices; ++i) {
    if (kFrom + i * kSpacing > kPadEnd) {
      const double delta = kRange * unit(rng);
      const double sign_draw = 2.0 * unit(rng) - 1.0;
      const bool down =
          sign_draw < (slope - 0.5 * (kMin + kMax)) / (0.5 * (kMax - kMin));
      slope += down ? -delta : delta;
      height += slope * kSpacing;
    }
    model.ground_heights.push_back(height);
  }
}

void TerrainBipedEnv::ResetState(std::mt19937_64& rng, std::vector<double>& q,
                                 std::vector<double>& qd) {
  // The simulator cycles through 20 evenly spaced clip phases, episode by
  // episode; one of them at random here.
  clip_start_ =
      std::uniform_int_distribution<int>(0, 19)(rng) / 20.0 * kWalkCycleSeconds;
  TerrainBipedPose pose = WalkPose(clip_start_);
  const TerrainBipedPose rate = WalkPoseRate(clip_start_);
  pose.root_x = 0.0;
  const auto placed = PlaceBodies(pose);
  double lowest = placed[0].y;
  for (int b = 0; b < kTerrainBipedBodies; ++b) {
    lowest = std::min(lowest, LowestCorner(b, placed[b]));
  }
  pose.root_y += kResetClearance - lowest;
  q = {pose.root_x, pose.root_y, -pose.root_angle};
  qd = {rate.root_x, rate.root_y, -rate.root_angle};
  for (int j = 0; j < kTerrainBipedJoints; ++j) {
    q.push_back(pose.joints[j]);
    qd.push_back(rate.joints[j]);
  }
}

void TerrainBipedEnv::BeginEpisode(const BulletWorld& world) {
  steps_ = 0;
  root_x_at_check_ = world.q(0);
  ending_ = TerrainBipedEnding::kNone;
}

void TerrainBipedEnv::Torques(const BulletWorld& world,
                              absl::Span<const double> clipped,
                              std::vector<double>& torques) const {
  const auto& joints = TerrainBipedJointDefs();
  for (int j = 0; j < kTerrainBipedJoints; ++j) {
    const TerrainBipedJoint& joint = joints[j + 1];
    const double torque =
        joint.kp * (clipped[j] - world.q(3 + j)) - joint.kd * world.qd(3 + j);
    torques[j] = std::clamp(torque, -joint.torque_limit, joint.torque_limit);
  }
}

StepResult TerrainBipedEnv::Evaluate(const BulletWorld& world,
                                     absl::Span<const double>) {
  ++steps_;
  StepResult result;
  bool fell = false;
  for (int b = 0; b < kTerrainBipedBodies; ++b) {
    fell = fell ||
           (TerrainBipedBodyDefs()[b].fall_contact && world.TouchesGround(b));
  }
  const double time = clip_time();
  result.reward = fell ? 0.0
                       : TerrainBipedImitationReward(
                             Pose(world), PoseRate(world), WalkPose(time),
                             WalkPoseRate(time),
                             [&](double x) { return world.GroundHeight(x); });
  bool stuck = false;
  if (stuck_steps_ > 0 && steps_ % stuck_steps_ == 0) {
    stuck = std::abs(world.q(0) - root_x_at_check_) < config_.stuck_distance;
    root_x_at_check_ = world.q(0);
  }
  ending_ = fell    ? TerrainBipedEnding::kFell
            : stuck ? TerrainBipedEnding::kStuck
                    : TerrainBipedEnding::kNone;
  result.terminated = fell || stuck;
  return result;
}

void TerrainBipedEnv::Observe(const BulletWorld& world,
                              double* observation) const {
  const TerrainBipedPose pose = Pose(world);
  const auto placed = PlaceBodies(pose);
  const auto moving = MoveBodies(pose, PoseRate(world));
  double* out = observation;
  *out++ = pose.root_y - world.GroundHeight(pose.root_x);
  for (const BoxPlacement& body : placed) {
    *out++ = body.x - pose.root_x;
    *out++ = body.y - pose.root_y;
  }
  for (const BoxMotion& body : moving) {
    *out++ = body.vx;
    *out++ = body.vy;
  }
  const double phase = std::fmod(clip_time(), kWalkCycleSeconds);
  *out++ = phase;
  const int bin =
      std::min(kPhaseBins - 1, static_cast<int>(phase * kPhaseBins));
  for (int i = 0; i < kPhaseBins; ++i) *out++ = i == bin ? 1.0 : 0.0;
}

std::string TerrainBipedEnv::TaskSignature() const {
  return absl::StrCat(config_.name, ";", config_.max_episode_steps, ";",
                      config_.stuck_distance, ";", config_.stuck_seconds, ";",
                      config_.incline);
}

absl::StatusOr<std::unique_ptr<Environment>> MakeTerrainBipedFlat() {
  absl::StatusOr<std::unique_ptr<TerrainBipedEnv>> env =
      TerrainBipedEnv::Create(TerrainBipedConfig());
  if (!env.ok()) return env.status();
  return std::unique_ptr<Environment>(std::move(*env));
}

absl::StatusOr<std::unique_ptr<Environment>> MakeTerrainBipedIncline() {
  TerrainBipedConfig config;
  config.name = "TerrainBipedIncline";
  config.incline = true;
  absl::StatusOr<std::unique_ptr<TerrainBipedEnv>> env =
      TerrainBipedEnv::Create(config);
  if (!env.ok()) return env.status();
  return std::unique_ptr<Environment>(std::move(*env));
}

}  // namespace vantage
