#include "actor/envs/bullet/biped_walk.h"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "common/util/state_bytes.h"

namespace vantage {

const std::array<const char*, kBipedHinges> kBipedHingeNames = {
    "waist",     "left_hip",      "left_knee",     "left_ankle",
    "left_toe",  "right_hip",     "right_knee",    "right_ankle",
    "right_toe", "left_shoulder", "right_shoulder"};

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kVelocityClip = 10.0;
// The standing root point (pelvis centre), and how far the toe tips reach
// forward, which an incline lifts the start by.
constexpr double kStandingRootZ = 1.0;
constexpr double kToeTipX = 0.245;
constexpr double kStartClearance = 0.005;

// Link indices of the feet and toes (hinge j drives link j + 1).
constexpr int kLeftFoot = 4;
constexpr int kLeftToe = 5;
constexpr int kRightFoot = 8;
constexpr int kRightToe = 9;
constexpr int kTorso = 1;

struct HingeSpec {
  double gear;   // N m at |action| 1
  double lower;  // radians
  double upper;
  double damping;  // N m s / rad
};

// Gears sized for a 36 kg body: legs strong enough to stand on one, the
// toes and arms light. No armature: its rotors would cost 3x the step time.
constexpr HingeSpec kWaist = {60.0, -0.5, 1.0, 1.0};
constexpr HingeSpec kHip = {100.0, -0.6, 2.0, 1.0};
constexpr HingeSpec kKnee = {100.0, -0.05, 2.5, 1.0};
constexpr HingeSpec kAnkle = {50.0, -0.8, 0.8, 0.5};
constexpr HingeSpec kToe = {15.0, -0.4, 1.0, 0.05};
constexpr HingeSpec kShoulder = {30.0, -1.0, 2.5, 0.2};

PlanarLink Capsule(const char* name, double from_x, double from_z, double to_x,
                   double to_z, double radius) {
  PlanarLink link;
  link.name = name;
  link.from_x = from_x;
  link.from_z = from_z;
  link.to_x = to_x;
  link.to_z = to_z;
  link.radius = radius;
  return link;
}

PlanarLink Hinged(PlanarLink link, int parent, double joint_x, double joint_z,
                  double axis, const HingeSpec& hinge) {
  link.parent = parent;
  link.joint_x = joint_x;
  link.joint_z = joint_z;
  link.axis = axis;
  link.lower = hinge.lower;
  link.upper = hinge.upper;
  link.damping = hinge.damping;
  return link;
}

// Standing straight with the soles on z = 0, then lifted by `lift`. Hinge
// axes are chosen so that the positive directions are the ones listed in
// biped_walk.h: for a segment hanging down, a rotation about -y swings it
// forward; for one standing up, a rotation about +y leans it forward.
PlanarModel BipedModel(double slope, double lift) {
  PlanarModel model;
  model.root_z = kStandingRootZ + lift;
  model.slope = slope;
  model.timestep = 0.002;
  const auto z = [lift](double value) { return value + lift; };
  std::vector<PlanarLink>& links = model.links;
  links.push_back(Capsule("pelvis", 0, z(0.95), 0, z(1.05), 0.08));
  links.push_back(Hinged(Capsule("torso", 0, z(1.12), 0, z(1.45), 0.08), 0, 0,
                         z(1.05), 1.0, kWaist));
  for (const char* side : {"left", "right"}) {
    const int thigh = static_cast<int>(links.size());
    const auto name = [side](const char* part) {
      return absl::StrCat(side, "_", part);
    };
    PlanarLink link = Hinged(Capsule("", 0, z(0.92), 0, z(0.55), 0.06), 0, 0,
                             z(0.95), -1.0, kHip);
    link.name = name("thigh");
    links.push_back(link);
    link = Hinged(Capsule("", 0, z(0.53), 0, z(0.13), 0.045), thigh, 0, z(0.53),
                  1.0, kKnee);
    link.name = name("shin");
    links.push_back(link);
    link = Hinged(Capsule("", -0.06, z(0.045), 0.10, z(0.045), 0.045),
                  thigh + 1, 0, z(0.09), -1.0, kAnkle);
    link.name = name("foot");
    link.friction = 1.0;
    links.push_back(link);
    link = Hinged(Capsule("", 0.16, z(0.045), 0.20, z(0.045), 0.045), thigh + 2,
                  0.13, z(0.045), -1.0, kToe);
    link.name = name("toe");
    link.friction = 1.0;
    links.push_back(link);
  }
  for (const char* name : {"left_arm", "right_arm"}) {
    links.push_back(Hinged(Capsule(name, 0, z(1.40), 0, z(1.05), 0.035), kTorso,
                           0, z(1.42), -1.0, kShoulder));
  }
  return model;
}

std::vector<double> BipedGears() {
  return {kWaist.gear, kHip.gear,      kKnee.gear,    kAnkle.gear,
          kToe.gear,   kHip.gear,      kKnee.gear,    kAnkle.gear,
          kToe.gear,   kShoulder.gear, kShoulder.gear};
}

EnvSpec BipedSpec(const BipedWalkConfig& config) {
  EnvSpec spec;
  spec.name = config.name;
  spec.observation_size = BipedWalkEnv::kObservationSize;
  spec.max_episode_steps = config.max_episode_steps;
  return spec;
}

}  // namespace

absl::Status BipedWalkConfig::Validate() const {
  const auto bad = [&](absl::string_view field, absl::string_view why) {
    return absl::InvalidArgumentError(
        absl::StrCat("biped walk config: ", field, " ", why));
  };
  if (name.empty()) return bad("name", "must not be empty");
  if (!(slope_degrees >= 0.0 && slope_degrees < 30.0)) {
    return bad("slope_degrees", "must be in [0, 30)");
  }
  if (!(min_root_height > 0.0)) return bad("min_root_height", "must be > 0");
  if (!(max_torso_pitch > 0.0)) return bad("max_torso_pitch", "must be > 0");
  if (!(stuck_distance > 0.0)) return bad("stuck_distance", "must be > 0");
  if (!(stuck_seconds >= 0.0)) {
    return bad("stuck_seconds", "must be >= 0 (0: never stuck)");
  }
  if (!std::isfinite(alive_bonus)) return bad("alive_bonus", "must be finite");
  if (!(ctrl_cost >= 0.0)) return bad("ctrl_cost", "must be >= 0");
  if (!(angle_noise >= 0.0) || !(velocity_noise >= 0.0)) {
    return bad("angle_noise and velocity_noise", "must be >= 0");
  }
  if (max_episode_steps < 0) {
    return bad("max_episode_steps", "must be >= 0 (0: no limit)");
  }
  return absl::OkStatus();
}

absl::StatusOr<std::unique_ptr<BipedWalkEnv>> BipedWalkEnv::Create(
    const BipedWalkConfig& config) {
  if (absl::Status status = config.Validate(); !status.ok()) return status;
  const double slope = config.slope_degrees * kPi / 180.0;
  PlanarModel model =
      BipedModel(slope, kStartClearance + kToeTipX * std::tan(slope));
  if (absl::Status status = ValidatePlanarModel(model); !status.ok()) {
    return status;
  }
  return std::unique_ptr<BipedWalkEnv>(
      new BipedWalkEnv(config, std::move(model)));
}

BipedWalkEnv::BipedWalkEnv(const BipedWalkConfig& config, PlanarModel model)
    : BulletEnv(BipedSpec(config), std::move(model), BipedGears(), kFrameSkip),
      config_(config),
      stuck_steps_(static_cast<int64_t>(
          std::llround(config.stuck_seconds / spec().control_dt))),
      cos_slope_(std::cos(this->model().slope)),
      sin_slope_(std::sin(this->model().slope)) {}

double BipedWalkEnv::Progress(const BulletWorld& world) const {
  return world.q(0) * cos_slope_ + world.q(1) * sin_slope_;
}

void BipedWalkEnv::ResetState(std::mt19937_64& rng, std::vector<double>& q,
                              std::vector<double>& qd) {
  std::uniform_real_distribution<double> angle(-config_.angle_noise,
                                               config_.angle_noise);
  std::uniform_real_distribution<double> velocity(-config_.velocity_noise,
                                                  config_.velocity_noise);
  for (size_t i = 3; i < q.size(); ++i) q[i] += angle(rng);
  for (double& value : qd) value += velocity(rng);
}

void BipedWalkEnv::BeginEpisode(const BulletWorld& world) {
  best_progress_ = Progress(world);
  steps_since_progress_ = 0;
  ending_ = BipedEnding::kNone;
  left_contact_ = false;
  right_contact_ = false;
}

void BipedWalkEnv::BeforeStep(const BulletWorld& world) {
  progress_before_ = Progress(world);
}

StepResult BipedWalkEnv::Evaluate(const BulletWorld& world,
                                  absl::Span<const double> action) {
  left_contact_ =
      world.TouchesGround(kLeftFoot) || world.TouchesGround(kLeftToe);
  right_contact_ =
      world.TouchesGround(kRightFoot) || world.TouchesGround(kRightToe);
  const double progress = Progress(world);
  if (progress >= best_progress_ + config_.stuck_distance) {
    best_progress_ = progress;
    steps_since_progress_ = 0;
  } else {
    ++steps_since_progress_;
  }
  const double height = world.q(1) - world.GroundHeight(world.q(0));
  const bool fell =
      !(height >= config_.min_root_height) ||
      !(std::fabs(world.LinkPitch(kTorso)) <= config_.max_torso_pitch);
  const bool stuck = stuck_steps_ > 0 && steps_since_progress_ >= stuck_steps_;
  ending_ = fell ? BipedEnding::kFell
                 : (stuck ? BipedEnding::kStuck : BipedEnding::kNone);
  double effort = 0.0;
  for (double a : action) effort += a * a;
  StepResult result;
  result.reward = (progress - progress_before_) / spec().control_dt +
                  config_.alive_bonus - config_.ctrl_cost * effort;
  result.terminated = fell || stuck;
  return result;
}

void BipedWalkEnv::Observe(const BulletWorld& world,
                           double* observation) const {
  const auto clip = [](double v) {
    return std::clamp(v, -kVelocityClip, kVelocityClip);
  };
  *observation++ = world.q(1) - world.GroundHeight(world.q(0));
  *observation++ = world.q(2);
  for (int i = 0; i < 3; ++i) *observation++ = clip(world.qd(i));
  for (int i = 3; i < world.num_dofs(); ++i) *observation++ = world.q(i);
  for (int i = 3; i < world.num_dofs(); ++i) *observation++ = clip(world.qd(i));
  *observation++ = left_contact_ ? 1.0 : 0.0;
  *observation++ = right_contact_ ? 1.0 : 0.0;
}

std::string BipedWalkEnv::TaskSignature() const {
  StateWriter writer("biped_walk_config", 1);
  writer.PutDoubles(
      {config_.slope_degrees, config_.min_root_height, config_.max_torso_pitch,
       config_.stuck_distance, config_.stuck_seconds, config_.alive_bonus,
       config_.ctrl_cost, config_.angle_noise, config_.velocity_noise});
  writer.PutI64(config_.max_episode_steps);
  return std::move(writer).Finish();
}

absl::StatusOr<std::unique_ptr<Environment>> MakeBipedWalkFlat() {
  BipedWalkConfig config;
  config.name = "BipedWalkFlat";
  absl::StatusOr<std::unique_ptr<BipedWalkEnv>> env =
      BipedWalkEnv::Create(config);
  if (!env.ok()) return env.status();
  return std::unique_ptr<Environment>(std::move(*env));
}

absl::StatusOr<std::unique_ptr<Environment>> MakeBipedWalkIncline() {
  BipedWalkConfig config;
  config.name = "BipedWalkIncline";
  config.slope_degrees = 5.0;
  absl::StatusOr<std::unique_ptr<BipedWalkEnv>> env =
      BipedWalkEnv::Create(config);
  if (!env.ok()) return env.status();
  return std::unique_ptr<Environment>(std::move(*env));
}

}  // namespace vantage
