#include "actor/envs/bullet/bullet_hopper.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "actor/envs/bullet/bullet_env.h"

namespace vantage {
namespace {

constexpr double kDegree = 3.14159265358979323846 / 180.0;
constexpr int kFrameSkip = 4;
constexpr double kGear = 200.0;
constexpr double kCtrlCost = 1e-3;
constexpr double kHealthyReward = 1.0;
constexpr double kMinZ = 0.7;
constexpr double kMaxAngle = 0.2;
constexpr double kStateLimit = 100.0;
constexpr double kVelocityClip = 10.0;
constexpr double kResetNoise = 5e-3;

// hopper.xml in world coordinates: the torso's centre (1.25 m) is the root
// point; the hinges' axes are -y as in the MJCF.
PlanarModel HopperModel() {
  PlanarModel model;
  model.root_z = 1.25;
  model.timestep = 0.002;
  PlanarLink torso;
  torso.name = "torso";
  torso.from_z = 1.45;
  torso.to_z = 1.05;
  torso.radius = 0.05;
  const auto hinge = [](const char* name, int parent, double joint_z,
                        double lower, double upper) {
    PlanarLink link;
    link.name = name;
    link.parent = parent;
    link.joint_z = joint_z;
    link.axis = -1.0;
    link.lower = lower * kDegree;
    link.upper = upper * kDegree;
    link.damping = 1.0;
    link.armature = 1.0;
    return link;
  };
  PlanarLink thigh = hinge("thigh", 0, 1.05, -150, 0);
  thigh.from_z = 1.05;
  thigh.to_z = 0.6;
  thigh.radius = 0.05;
  PlanarLink leg = hinge("leg", 1, 0.6, -150, 0);
  leg.from_z = 0.6;
  leg.to_z = 0.1;
  leg.radius = 0.04;
  PlanarLink foot = hinge("foot", 2, 0.1, -45, 45);
  foot.from_x = -0.13;
  foot.to_x = 0.26;
  foot.from_z = foot.to_z = 0.1;
  foot.radius = 0.06;
  foot.friction = 2.0;
  model.links = {torso, thigh, leg, foot};
  return model;
}

class BulletHopper : public BulletEnv {
 public:
  explicit BulletHopper(PlanarModel model)
      : BulletEnv(Spec(), std::move(model), {kGear, kGear, kGear}, kFrameSkip) {
  }

 private:
  static EnvSpec Spec() {
    EnvSpec spec;
    spec.name = "BulletHopper";
    spec.observation_size = 11;
    spec.max_episode_steps = 1000;
    return spec;
  }

  void ResetState(std::mt19937_64& rng, std::vector<double>& q,
                  std::vector<double>& qd) override {
    std::uniform_real_distribution<double> noise(-kResetNoise, kResetNoise);
    for (double& value : q) value += noise(rng);
    for (double& value : qd) value += noise(rng);
  }

  void BeforeStep(const BulletWorld& world) override { x_before_ = world.q(0); }

  StepResult Evaluate(const BulletWorld& world,
                      absl::Span<const double> action) override {
    double effort = 0.0;
    for (double a : action) effort += a * a;
    StepResult result;
    result.reward = (world.q(0) - x_before_) / spec().control_dt +
                    kHealthyReward - kCtrlCost * effort;
    result.terminated = !Healthy(world);
    return result;
  }

  static bool Healthy(const BulletWorld& world) {
    for (int i = 2; i < world.num_dofs(); ++i) {
      if (!(std::fabs(world.q(i)) < kStateLimit)) return false;
    }
    for (int i = 0; i < world.num_dofs(); ++i) {
      if (!(std::fabs(world.qd(i)) < kStateLimit)) return false;
    }
    return world.q(1) > kMinZ && std::fabs(world.q(2)) < kMaxAngle;
  }

  void Observe(const BulletWorld& world, double* observation) const override {
    for (int i = 1; i < world.num_dofs(); ++i) *observation++ = world.q(i);
    for (int i = 0; i < world.num_dofs(); ++i) {
      *observation++ = std::clamp(world.qd(i), -kVelocityClip, kVelocityClip);
    }
  }

  // Written by BeforeStep before every read: not state.
  double x_before_ = 0.0;
};

}  // namespace

absl::StatusOr<std::unique_ptr<Environment>> MakeBulletHopper() {
  PlanarModel model = HopperModel();
  if (absl::Status status = ValidatePlanarModel(model); !status.ok()) {
    return status;
  }
  return std::unique_ptr<Environment>(new BulletHopper(std::move(model)));
}

}  // namespace vantage
