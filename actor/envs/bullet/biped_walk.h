#ifndef VANTAGE_ACTOR_ENVS_BULLET_BIPED_WALK_H_
#define VANTAGE_ACTOR_ENVS_BULLET_BIPED_WALK_H_

// The fragile biped of the paper's risk-averse experiment (after Terrain
// RL's planar biped), rebuilt on Bullet: a planar character of 12 capsules
// (pelvis = root, torso, two arms, two legs of thigh, shin, foot and toe,
// 36 kg, 1.53 m) with 11 torque-driven hinges, walking on flat ground or up
// an incline. README.md ("Bullet tasks") lists the hinges and rules.

#include <array>
#include <cstdint>
#include <memory>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "actor/envs/bullet/bullet_env.h"

namespace vantage {

// The hinges in action and observation order. Angles are 0 when standing
// straight; positive means: waist - the torso leans forward; hip - the
// thigh swings forward; knee - the shin folds back; ankle, toe - up;
// shoulder - the arm swings forward.
inline constexpr int kBipedHinges = 11;
extern const std::array<const char*, kBipedHinges> kBipedHingeNames;

struct BipedWalkConfig {
  std::string name = "BipedWalkFlat";
  // The ground rises towards +x by this angle; progress is measured along
  // it.
  double slope_degrees = 0.0;
  // Fall: the root point below this height above the ground under it, or
  // the torso's pitch beyond +-max_torso_pitch (radians).
  double min_root_height = 0.7;
  double max_torso_pitch = 1.0;
  // Stuck: less than stuck_distance metres of progress beyond the best so
  // far within stuck_seconds (0 turns the rule off).
  double stuck_distance = 0.1;
  double stuck_seconds = 2.0;
  // reward = progress velocity + alive_bonus - ctrl_cost |a|^2.
  double alive_bonus = 0.2;
  double ctrl_cost = 1e-3;
  // Uniform noise on the initial hinge angles (radians) and on every
  // initial velocity (rad/s, m/s).
  double angle_noise = 0.02;
  double velocity_noise = 0.05;
  int64_t max_episode_steps = 1000;

  // Explains the first broken rule: a name, slope in [0, 30) degrees,
  // positive thresholds and noise >= 0.
  absl::Status Validate() const;
};

// Why the last step ended the episode (kNone if it did not).
enum class BipedEnding { kNone, kFell, kStuck };

// Observation (29): root height above the ground under it, root pitch,
// root velocity (x, z) and pitch rate, the 11 hinge angles, the 11 hinge
// velocities, and left and right foot contact (1 if the foot or its toe
// touched the ground in the step's last physics step, else 0); velocities
// clipped to +-10.
// Nothing absolute: no x, no time.
class BipedWalkEnv : public BulletEnv {
 public:
  static constexpr int kObservationSize = 29;
  static constexpr int kFrameSkip = 10;  // 0.002 s x 10: 50 Hz control

  static absl::StatusOr<std::unique_ptr<BipedWalkEnv>> Create(
      const BipedWalkConfig& config);

  const BipedWalkConfig& config() const { return config_; }
  BipedEnding ending() const { return ending_; }
  // How far the root point is along the ground's uphill direction.
  double Progress(const BulletWorld& world) const;

 private:
  BipedWalkEnv(const BipedWalkConfig& config, PlanarModel model);

  void ResetState(std::mt19937_64& rng, std::vector<double>& q,
                  std::vector<double>& qd) override;
  void BeginEpisode(const BulletWorld& world) override;
  void BeforeStep(const BulletWorld& world) override;
  StepResult Evaluate(const BulletWorld& world,
                      absl::Span<const double> action) override;
  void Observe(const BulletWorld& world, double* observation) const override;
  std::string TaskSignature() const override;

  BipedWalkConfig config_;
  int64_t stuck_steps_;  // stuck_seconds in steps (0: never)
  double cos_slope_;
  double sin_slope_;
  // Episode state; Replay rebuilds it.
  double progress_before_ = 0.0;
  double best_progress_ = 0.0;
  int64_t steps_since_progress_ = 0;
  BipedEnding ending_ = BipedEnding::kNone;
  bool left_contact_ = false;
  bool right_contact_ = false;
};

absl::StatusOr<std::unique_ptr<Environment>> MakeBipedWalkFlat();
// 5 degrees uphill.
absl::StatusOr<std::unique_ptr<Environment>> MakeBipedWalkIncline();

}  // namespace vantage

#endif  // VANTAGE_ACTOR_ENVS_BULLET_BIPED_WALK_H_
