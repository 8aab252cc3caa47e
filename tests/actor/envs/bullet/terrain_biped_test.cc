#include "actor/envs/bullet/terrain_biped.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace vantage {
namespace {

constexpr double kControlDt =
    TerrainBipedEnv::kPhysicsStep * TerrainBipedEnv::kFrameSkip;

std::unique_ptr<TerrainBipedEnv> Make(
    const TerrainBipedConfig& config = TerrainBipedConfig()) {
  absl::StatusOr<std::unique_ptr<TerrainBipedEnv>> env =
      TerrainBipedEnv::Create(config);
  EXPECT_TRUE(env.ok()) << env.status();
  return env.ok() ? std::move(*env) : nullptr;
}

// The clip's joint angles of the step's end, as PD targets.
std::vector<double> ClipTargets(const TerrainBipedEnv& env) {
  const TerrainBipedPose next = WalkPose(env.clip_time() + kControlDt);
  return std::vector<double>(next.joints.begin(), next.joints.end());
}

struct Episode {
  int steps = 0;
  double reward = 0.0;
  double distance = 0.0;
  TerrainBipedEnding ending = TerrainBipedEnding::kNone;
};

template <typename Policy>
Episode RunEpisode(TerrainBipedEnv& env, uint64_t seed, Policy policy) {
  std::vector<double> observation(TerrainBipedEnv::kObservationSize);
  EXPECT_TRUE(env.Reset(seed, absl::MakeSpan(observation)).ok());
  Episode episode;
  StepResult result;
  while (!result.terminated && episode.steps < 256) {
    absl::StatusOr<StepResult> step =
        env.Step(policy(env), absl::MakeSpan(observation));
    EXPECT_TRUE(step.ok()) << step.status();
    if (!step.ok()) break;
    result = *step;
    episode.reward += result.reward;
    ++episode.steps;
    // A fall earns nothing.
    if (env.ending() == TerrainBipedEnding::kFell) {
      EXPECT_EQ(result.reward, 0.0);
    }
  }
  episode.distance = env.world()->q(0);
  episode.ending = env.ending();
  return episode;
}

TEST(TerrainBipedTest, SpecIsTheSimulators) {
  auto env = Make();
  const EnvSpec& spec = env->spec();
  EXPECT_EQ(spec.name, "TerrainBipedFlat");
  EXPECT_EQ(spec.observation_size, 54);
  EXPECT_EQ(spec.action_size, 11);
  EXPECT_EQ(spec.max_episode_steps, 256);
  EXPECT_NEAR(spec.control_dt, 1.0 / 30, 1e-12);
  // Knee: limits [-3, 0], bounds -1.5 -+ 6.
  EXPECT_NEAR(spec.action_low[1], -7.5, 1e-12);
  EXPECT_NEAR(spec.action_high[1], 4.5, 1e-12);
}

// Bullet's bodies are where the character's kinematics put them: the
// model's joints, offsets and angle conventions agree with the data.
TEST(TerrainBipedTest, BulletsBodiesAreWhereTheKinematicsSay) {
  auto env = Make();
  std::vector<double> observation(TerrainBipedEnv::kObservationSize);
  ASSERT_TRUE(env->Reset(3, absl::MakeSpan(observation)).ok());
  for (int step = 0; step < 8; ++step) {
    const BulletWorld& world = *env->world();
    const auto placed = PlaceBodies(env->Pose(world));
    for (int b = 0; b < kTerrainBipedBodies; ++b) {
      const CapsulePose drawn = world.LinkCapsule(b);
      EXPECT_NEAR((drawn.from_x + drawn.to_x) / 2, placed[b].x, 1e-5) << b;
      EXPECT_NEAR((drawn.from_z + drawn.to_z) / 2, placed[b].y, 1e-5) << b;
    }
    ASSERT_TRUE(env->Step(ClipTargets(*env), absl::MakeSpan(observation)).ok());
  }
  // Observation: root height, then the torso's centre 0.19 m up the
  // (nearly upright) torso from the root.
  EXPECT_NEAR(observation[0], env->world()->q(1), 1e-12);
  EXPECT_NEAR(observation[2], 0.19, 0.02);
  // The phase and its one-hot quarter.
  const double phase = observation[49];
  EXPECT_GE(phase, 0.0);
  EXPECT_LT(phase, 1.0);
  EXPECT_EQ(observation[50 + static_cast<int>(phase * 4)], 1.0);
}

TEST(TerrainBipedTest, TheClipScoresOneAgainstItself) {
  for (double time : {0.0, 0.33, 0.71}) {
    EXPECT_NEAR(TerrainBipedImitationReward(WalkPose(time), WalkPoseRate(time),
                                            WalkPose(time), WalkPoseRate(time)),
                1.0, 1e-12);
  }
  // A bent knee costs pose and end-effector reward.
  TerrainBipedPose bent = WalkPose(0.2);
  bent.joints[1] -= 0.5;
  const double reward = TerrainBipedImitationReward(
      bent, WalkPoseRate(0.2), WalkPose(0.2), WalkPoseRate(0.2));
  EXPECT_LT(reward, 0.95);
  EXPECT_GT(reward, 0.3);
}

// Playing the clip open loop walks forward for a while, imitating it
// well, before the character (with no feedback) falls; random targets
// fall sooner and imitate nothing. Measured: tracking 23-42 steps at
// 0.65-0.72 a step and 0.4-1.6 m, random 10-24 steps at about 0.25.
TEST(TerrainBipedTest, PlayingTheClipWalksUntilItFalls) {
  auto env = Make();
  std::mt19937_64 rng(1);
  for (uint64_t seed = 0; seed < 5; ++seed) {
    const Episode tracking = RunEpisode(*env, seed, ClipTargets);
    EXPECT_GE(tracking.steps, 15) << seed;
    EXPECT_GT(tracking.reward / tracking.steps, 0.55) << seed;
    EXPECT_GT(tracking.distance, 0.3) << seed;
    EXPECT_EQ(tracking.ending, TerrainBipedEnding::kFell) << seed;
    const Episode random =
        RunEpisode(*env, seed, [&](const TerrainBipedEnv& e) {
          std::vector<double> action(kTerrainBipedJoints);
          for (int j = 0; j < kTerrainBipedJoints; ++j) {
            action[j] = std::uniform_real_distribution<double>(
                e.spec().action_low[j], e.spec().action_high[j])(rng);
          }
          return action;
        });
    EXPECT_LT(random.reward / random.steps, 0.4) << seed;
    EXPECT_EQ(random.ending, TerrainBipedEnding::kFell) << seed;
  }
}

// The simulator's incline: level to x = 1 m, then a slope wandering about
// a grade of 0.175, new every episode and the same for the same seed.
TEST(TerrainBipedTest, TheInclineRisesAtAboutAGradeOf0point175) {
  TerrainBipedConfig config;
  config.name = "TerrainBipedIncline";
  config.incline = true;
  auto env = Make(config);
  std::vector<double> observation(TerrainBipedEnv::kObservationSize);
  std::vector<double> at_ten;
  for (uint64_t seed : {1, 2, 1}) {
    ASSERT_TRUE(env->Reset(seed, absl::MakeSpan(observation)).ok());
    const BulletWorld& world = *env->world();
    EXPECT_EQ(world.GroundHeight(-1.0), 0.0);
    EXPECT_EQ(world.GroundHeight(0.9), 0.0);
    const double grade =
        (world.GroundHeight(20.5) - world.GroundHeight(1.5)) / 19.0;
    EXPECT_GT(grade, 0.15) << seed;
    EXPECT_LT(grade, 0.2) << seed;
    at_ten.push_back(world.GroundHeight(10.0));
    // The observation's first value is the height above the ground.
    EXPECT_NEAR(observation[0], world.q(1) - world.GroundHeight(world.q(0)),
                1e-12);
  }
  EXPECT_NE(at_ten[0], at_ten[1]);
  EXPECT_EQ(at_ten[0], at_ten[2]);
  // Playing the clip, the character walks onto the slope before it falls.
  double furthest = 0.0;
  for (uint64_t seed = 0; seed < 5; ++seed) {
    const Episode episode = RunEpisode(*env, seed, ClipTargets);
    EXPECT_GT(episode.steps, 5) << seed;
    furthest = std::max(furthest, episode.distance);
  }
  EXPECT_GT(furthest, 1.0);
}

TEST(TerrainBipedTest, AStuckCharacterEndsTheEpisode) {
  TerrainBipedConfig config;
  config.stuck_seconds = 0.2;  // 6 steps
  config.stuck_distance = 100.0;
  auto env = Make(config);
  const Episode episode = RunEpisode(*env, 1, ClipTargets);
  EXPECT_EQ(episode.steps, 6);
  EXPECT_EQ(episode.ending, TerrainBipedEnding::kStuck);
  config.stuck_seconds = -1;
  EXPECT_FALSE(TerrainBipedEnv::Create(config).ok());
}

}  // namespace
}  // namespace vantage
