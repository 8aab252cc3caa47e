#include "actor/envs/bullet/bullet_hopper.h"

#include <memory>
#include <random>
#include <vector>

#include "actor/envs/env_registry.h"
#include "gtest/gtest.h"

namespace vantage {
namespace {

struct Summary {
  double mean_return = 0.0;
  double mean_length = 0.0;
};

// Episodes of the uniform random policy (or of zero actions), as the
// Gymnasium figures are usually quoted.
Summary Episodes(const std::string& name, int episodes, bool random) {
  absl::StatusOr<std::unique_ptr<Environment>> made = MakeEnvironment(name);
  EXPECT_TRUE(made.ok());
  Environment& env = **made;
  std::vector<double> observation(env.spec().observation_size);
  std::mt19937_64 rng(11);
  Summary summary;
  for (int e = 0; e < episodes; ++e) {
    EXPECT_TRUE(env.Reset(e, absl::MakeSpan(observation)).ok());
    for (int t = 0; t < 1000; ++t) {
      std::vector<double> action(env.spec().action_size, 0.0);
      if (random) {
        for (double& a : action) {
          a = std::uniform_real_distribution<double>(-1.0, 1.0)(rng);
        }
      }
      absl::StatusOr<StepResult> result =
          env.Step(action, absl::MakeSpan(observation));
      EXPECT_TRUE(result.ok()) << result.status();
      if (!result.ok()) break;
      summary.mean_return += result->reward / episodes;
      summary.mean_length += 1.0 / episodes;
      if (result->terminated || result->truncated) break;
    }
  }
  return summary;
}

TEST(BulletHopperTest, StartsStandingLikeTheMujocoHopper) {
  absl::StatusOr<std::unique_ptr<Environment>> env = MakeBulletHopper();
  ASSERT_TRUE(env.ok());
  std::vector<double> observation(11);
  ASSERT_TRUE((*env)->Reset(0, absl::MakeSpan(observation)).ok());
  // qpos[1:] = (z, pitch, thigh, leg, foot) near (1.25, 0, 0, 0, 0), qvel
  // near 0: the reset noise is +-5e-3.
  EXPECT_NEAR(observation[0], 1.25, 5e-3);
  for (int i = 1; i < 11; ++i) EXPECT_NEAR(observation[i], 0.0, 5e-3) << i;
  EXPECT_DOUBLE_EQ((*env)->spec().control_dt, 0.008);
}

// Zero actions: the hopper topples and the healthy rules end the episode,
// after a couple of seconds as in MuJoCo (183 steps there for seed 1).
TEST(BulletHopperTest, ZeroActionFallsAndTerminates) {
  const Summary summary = Episodes("BulletHopper", 3, /*random=*/false);
  EXPECT_GT(summary.mean_length, 50.0);
  EXPECT_LT(summary.mean_length, 500.0);
}

// The integration check against known behaviour: a random policy's
// episodes are as short and earn as much as on MuJoCo's Hopper.
TEST(BulletHopperTest, RandomPolicyMatchesTheMujocoHopper) {
  const Summary bullet = Episodes("BulletHopper", 50, /*random=*/true);
  const Summary mujoco = Episodes("Hopper", 50, /*random=*/true);
  EXPECT_GT(bullet.mean_return, 0.5 * mujoco.mean_return);
  EXPECT_LT(bullet.mean_return, 2.0 * mujoco.mean_return);
  EXPECT_GT(bullet.mean_length, 0.5 * mujoco.mean_length);
  EXPECT_LT(bullet.mean_length, 2.0 * mujoco.mean_length);
  EXPECT_GT(bullet.mean_return, 5.0);
  EXPECT_LT(bullet.mean_return, 60.0);
}

}  // namespace
}  // namespace vantage
