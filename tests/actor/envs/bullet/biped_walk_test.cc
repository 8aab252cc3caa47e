#include "actor/envs/bullet/biped_walk.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include "actor/envs/env_registry.h"
#include "common/env/time_limit.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace vantage {
namespace {

using ::testing::HasSubstr;

constexpr double kPi = 3.14159265358979323846;
// Observation layout.
constexpr int kHeight = 0;
constexpr int kPitch = 1;
constexpr int kLeftContact = 27;
constexpr int kRightContact = 28;

std::unique_ptr<BipedWalkEnv> Make(const BipedWalkConfig& config) {
  absl::StatusOr<std::unique_ptr<BipedWalkEnv>> env =
      BipedWalkEnv::Create(config);
  EXPECT_TRUE(env.ok()) << env.status();
  return env.ok() ? std::move(*env) : nullptr;
}

struct Episode {
  int steps = 0;
  StepResult last;
  std::vector<double> observation;
  double total_reward = 0.0;
};

template <typename Policy>
Episode Drive(Environment& env, uint64_t seed, int max_steps, Policy policy) {
  Episode episode;
  episode.observation.resize(env.spec().observation_size);
  EXPECT_TRUE(env.Reset(seed, absl::MakeSpan(episode.observation)).ok());
  while (episode.steps < max_steps) {
    absl::StatusOr<StepResult> result = env.Step(
        policy(episode.observation), absl::MakeSpan(episode.observation));
    EXPECT_TRUE(result.ok()) << result.status();
    if (!result.ok()) break;
    ++episode.steps;
    episode.last = *result;
    episode.total_reward += result->reward;
    if (result->terminated || result->truncated) break;
  }
  return episode;
}

std::vector<double> Zero(const std::vector<double>&) {
  return std::vector<double>(kBipedHinges, 0.0);
}

TEST(BipedWalkTest, ElevenNamedHinges) {
  const auto env = Make({});
  ASSERT_NE(env, nullptr);
  EXPECT_EQ(env->spec().action_size, kBipedHinges);
  EXPECT_EQ(env->gears().size(), static_cast<size_t>(kBipedHinges));
  EXPECT_EQ(env->model().links.size(), 12u);
  EXPECT_STREQ(kBipedHingeNames[0], "waist");
  EXPECT_STREQ(kBipedHingeNames[10], "right_shoulder");
  EXPECT_EQ(env->spec().observation_size, BipedWalkEnv::kObservationSize);
  EXPECT_DOUBLE_EQ(env->spec().control_dt, 0.02);
}

TEST(BipedWalkTest, ZeroTorquesFallAndTerminate) {
  for (const double slope : {0.0, 5.0}) {
    BipedWalkConfig config;
    config.slope_degrees = slope;
    const auto env = Make(config);
    for (uint64_t seed = 0; seed < 3; ++seed) {
      const Episode episode = Drive(*env, seed, 1000, Zero);
      EXPECT_TRUE(episode.last.terminated) << slope << " " << seed;
      EXPECT_FALSE(episode.last.truncated);
      EXPECT_LT(episode.steps, 100) << slope << " " << seed;
      EXPECT_EQ(env->ending(), BipedEnding::kFell);
      EXPECT_TRUE(episode.observation[kHeight] < config.min_root_height ||
                  std::fabs(env->world()->LinkPitch(1)) >
                      config.max_torso_pitch);
    }
  }
}

// Falling switched off (the thresholds out of reach), a biped without
// torques collapses and lies still: only the stuck rule can end that
// episode, exactly 100 steps (2 s) after the last step that brought 0.1 m
// of progress beyond the best so far.
BipedWalkConfig Harmless(double slope) {
  BipedWalkConfig config;
  config.slope_degrees = slope;
  config.min_root_height = 1e-6;
  config.max_torso_pitch = 100.0;
  return config;
}

TEST(BipedWalkTest, LyingStillGetsStuck) {
  for (const double slope : {0.0, 5.0}) {
    const auto env = Make(Harmless(slope));
    std::vector<double> observation(29);
    ASSERT_TRUE(env->Reset(1, absl::MakeSpan(observation)).ok());
    double best = env->Progress(*env->world());
    int last_progress = 0;
    int steps = 0;
    StepResult result;
    while (steps < 1000) {
      absl::StatusOr<StepResult> stepped = env->Step(
          std::vector<double>(kBipedHinges, 0.0), absl::MakeSpan(observation));
      ASSERT_TRUE(stepped.ok());
      result = *stepped;
      ++steps;
      const double progress = env->Progress(*env->world());
      if (progress >= best + 0.1) {
        best = progress;
        last_progress = steps;
      }
      if (result.terminated) break;
    }
    EXPECT_TRUE(result.terminated) << slope;
    EXPECT_EQ(env->ending(), BipedEnding::kStuck) << slope;
    EXPECT_EQ(steps, last_progress + 100) << slope;
    // It is down: the fall rule would have ended it long before.
    EXPECT_LT(observation[kHeight], 0.5) << slope;
  }
}

TEST(BipedWalkTest, TimeLimitTruncatesAt1000Steps) {
  BipedWalkConfig config = Harmless(0.0);
  config.stuck_seconds = 0.0;
  absl::StatusOr<std::unique_ptr<BipedWalkEnv>> inner =
      BipedWalkEnv::Create(config);
  ASSERT_TRUE(inner.ok());
  TimeLimit env(std::move(*inner));
  const Episode episode = Drive(env, 2, 5000, Zero);
  EXPECT_EQ(episode.steps, 1000);
  EXPECT_TRUE(episode.last.truncated);
  EXPECT_FALSE(episode.last.terminated);
  std::vector<double> observation(29);
  EXPECT_EQ(env.Step(std::vector<double>(11, 0.0), absl::MakeSpan(observation))
                .status()
                .code(),
            absl::StatusCode::kFailedPrecondition);
}

TEST(BipedWalkTest, RewardIsProgressVelocityPlusAliveMinusEffort) {
  for (const double slope : {0.0, 5.0}) {
    BipedWalkConfig config;
    config.slope_degrees = slope;
    const auto env = Make(config);
    std::vector<double> observation(29);
    ASSERT_TRUE(env->Reset(3, absl::MakeSpan(observation)).ok());
    const double theta = slope * kPi / 180.0;
    for (int t = 0; t < 20; ++t) {
      const BulletWorld& world = *env->world();
      const double x = world.q(0), z = world.q(1);
      std::vector<double> action(kBipedHinges, 0.0);
      action[1] = 0.5;  // swing the left leg forward
      action[6] = -0.3;
      double effort = 0.0;
      for (double a : action) effort += a * a;
      absl::StatusOr<StepResult> result =
          env->Step(action, absl::MakeSpan(observation));
      ASSERT_TRUE(result.ok());
      const double progress = (env->world()->q(0) - x) * std::cos(theta) +
                              (env->world()->q(1) - z) * std::sin(theta);
      EXPECT_NEAR(result->reward, progress / 0.02 + 0.2 - 1e-3 * effort, 1e-9);
      if (result->terminated) break;
    }
  }
}

// The observation holds nothing absolute: the root height is measured from
// the ground under the root, so on the incline it is the standing height
// while the root's world z depends on where it stands.
TEST(BipedWalkTest, ObservationIsRelativeToTheGround) {
  BipedWalkConfig config;
  config.slope_degrees = 5.0;
  const auto env = Make(config);
  const Episode episode = Drive(*env, 1, 3, Zero);
  ASSERT_EQ(episode.steps, 3);
  const BulletWorld& world = *env->world();
  const double tangent = std::tan(5.0 * kPi / 180.0);
  EXPECT_DOUBLE_EQ(world.GroundHeight(1.0), tangent);
  EXPECT_NEAR(episode.observation[kHeight], world.q(1) - world.q(0) * tangent,
              1e-12);
  EXPECT_NEAR(episode.observation[kHeight], 1.0, 0.03);
  EXPECT_NEAR(episode.observation[kPitch], world.q(2), 1e-12);
  // Landed on both feet (the incline starts the biped above its toes).
  EXPECT_EQ(episode.observation[kLeftContact], 1.0);
  EXPECT_EQ(episode.observation[kRightContact], 1.0);
}

TEST(BipedWalkTest, RandomTorquesEndEpisodesQuickly) {
  // "Fragile": flailing at random brings the biped down in well under the
  // stuck window.
  const auto env = Make({});
  std::mt19937_64 rng(3);
  int total = 0;
  for (uint64_t seed = 0; seed < 10; ++seed) {
    const Episode episode =
        Drive(*env, seed, 1000, [&rng](const std::vector<double>&) {
          std::vector<double> action(kBipedHinges);
          for (double& a : action) {
            a = std::uniform_real_distribution<double>(-1.0, 1.0)(rng);
          }
          return action;
        });
    EXPECT_TRUE(episode.last.terminated);
    EXPECT_EQ(env->ending(), BipedEnding::kFell);
    total += episode.steps;
  }
  EXPECT_LT(total, 10 * 60);
}

TEST(BipedWalkTest, ConfigsAreValidated) {
  EXPECT_TRUE(BipedWalkConfig{}.Validate().ok());
  BipedWalkConfig steep;
  steep.slope_degrees = 45.0;
  EXPECT_THAT(std::string(steep.Validate().message()),
              HasSubstr("slope_degrees must be in [0, 30)"));
  BipedWalkConfig negative;
  negative.stuck_seconds = -1.0;
  EXPECT_THAT(std::string(negative.Validate().message()),
              HasSubstr("stuck_seconds"));
  EXPECT_FALSE(BipedWalkEnv::Create(steep).ok());
}

TEST(BipedWalkTest, RegisteredVariants) {
  for (const char* name : {"BipedWalkFlat", "BipedWalkIncline"}) {
    absl::StatusOr<std::unique_ptr<Environment>> env = MakeEnvironment(name);
    ASSERT_TRUE(env.ok());
    const auto* limited = dynamic_cast<const TimeLimit*>(env->get());
    ASSERT_NE(limited, nullptr);
    const auto* biped = dynamic_cast<const BipedWalkEnv*>(&limited->inner());
    ASSERT_NE(biped, nullptr);
    EXPECT_EQ(biped->config().slope_degrees,
              std::string(name) == "BipedWalkIncline" ? 5.0 : 0.0);
    EXPECT_EQ(biped->spec().name, name);
  }
}

}  // namespace
}  // namespace vantage
