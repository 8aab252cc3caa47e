#ifndef VANTAGE_ACTOR_ENVS_BULLET_TERRAIN_BIPED_H_
#define VANTAGE_ACTOR_ENVS_BULLET_TERRAIN_BIPED_H_

// The Terrain RL simulator's planar biped walking task
// (UBCMOCCA/TerrainRLSim, PD_Biped2D_Flat-v0 and PD_Biped2D_Incline-v0),
// rebuilt on Bullet as far as
// its facts allow (docs/environments.md compares each item with its source
// file): the 12-box biped2D_full character, 11 PD targets per step at
// 30 Hz, a pose-only observation and the walking clip's imitation reward.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "absl/functional/function_ref.h"
#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "actor/envs/bullet/bullet_env.h"
#include "actor/envs/bullet/terrain_biped_character.h"

namespace vantage {

struct TerrainBipedConfig {
  std::string name = "TerrainBipedFlat";
  // The simulator's time_limit for the biped tasks (args/envs.json).
  int64_t max_episode_steps = 256;
  // Stuck: the root moved less than stuck_distance metres over the last
  // stuck_seconds (the simulator's fall-distance rule, which its biped
  // tasks leave off; the paper ends episodes that are stuck). 0: off.
  double stuck_distance = 0.5;
  double stuck_seconds = 5.0;
  // The simulator's inclines (data/terrain/inclines.txt): level up to
  // x = 1 m, then a slope that wanders about a grade of 0.175 (a new one
  // every episode); false: flat ground.
  bool incline = false;

  absl::Status Validate() const;
};

// Why the last step ended the episode (kNone if it did not).
enum class TerrainBipedEnding { kNone, kFell, kStuck };

// Observation (54), as the simulator's BuildPoliState: the root's height
// above the ground under it; every body's centre (x, y) relative to the
// root joint (12 x 2); every body's centre velocity (12 x 2); the clip's
// phase and its quarter as one-hot (5). No absolute position.
// Action (11): PD target angles of the joints in the character's order,
// within the simulator's controller bounds (mean -+ 2 x range).
class TerrainBipedEnv : public BulletEnv {
 public:
  static constexpr int kObservationSize = 54;
  // Physics at 3000 Hz, 100 steps per action: 30 Hz control.
  static constexpr double kPhysicsStep = 1.0 / 3000.0;
  static constexpr int kFrameSkip = 100;

  static absl::StatusOr<std::unique_ptr<TerrainBipedEnv>> Create(
      const TerrainBipedConfig& config);

  const TerrainBipedConfig& config() const { return config_; }
  TerrainBipedEnding ending() const { return ending_; }
  // The pose (and its rate) the world is in.
  TerrainBipedPose Pose(const BulletWorld& world) const;
  TerrainBipedPose PoseRate(const BulletWorld& world) const;
  // Clip time of the current step's reference pose.
  double clip_time() const { return clip_start_ + steps_ * control_dt_; }

 private:
  TerrainBipedEnv(const TerrainBipedConfig& config, PlanarModel model);

  void ShapeGround(std::mt19937_64& rng, PlanarModel& model) override;
  void ResetState(std::mt19937_64& rng, std::vector<double>& q,
                  std::vector<double>& qd) override;
  void BeginEpisode(const BulletWorld& world) override;
  StepResult Evaluate(const BulletWorld& world,
                      absl::Span<const double> action) override;
  void Observe(const BulletWorld& world, double* observation) const override;
  std::string TaskSignature() const override;
  // Explicit PD at every physics step, torques clamped to the limits.
  int TorqueSubsteps() const override { return 1; }
  void Torques(const BulletWorld& world, absl::Span<const double> clipped,
               std::vector<double>& torques) const override;

  TerrainBipedConfig config_;
  double control_dt_;
  int64_t stuck_steps_;  // stuck_seconds in steps (0: never)
  // Episode state; Replay rebuilds it.
  double clip_start_ = 0.0;
  int64_t steps_ = 0;
  double root_x_at_check_ = 0.0;
  TerrainBipedEnding ending_ = TerrainBipedEnding::kNone;
};

// The imitation reward of the simulator's cScenarioExpImitate::CalcReward
// for a simulated pose against the clip's at the same time: 0.5 pose +
// 0.05 velocity + 0.15 end effectors + 0.1 root height + 0.2 centre-of-mass
// velocity, each exp(-k x error). Exposed for its test.
// Heights of the simulated pose count from `ground` (the height at an x);
// the clip's from 0.
double TerrainBipedImitationReward(
    const TerrainBipedPose& pose, const TerrainBipedPose& rate,
    const TerrainBipedPose& reference, const TerrainBipedPose& reference_rate,
    absl::FunctionRef<double(double)> ground = [](double) { return 0.0; });

absl::StatusOr<std::unique_ptr<Environment>> MakeTerrainBipedFlat();
absl::StatusOr<std::unique_ptr<Environment>> MakeTerrainBipedIncline();

}  // namespace vantage

#endif  // VANTAGE_ACTOR_ENVS_BULLET_TERRAIN_BIPED_H_
