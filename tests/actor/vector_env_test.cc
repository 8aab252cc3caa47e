#include "actor/vector_env.h"

#include <cmath>
#include <random>
#include <vector>

#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace vantage {
namespace {

using ::testing::HasSubstr;

TEST(VectorEnvTest, AutoResetKeepsTheFinalObservation) {
  absl::StatusOr<std::unique_ptr<VectorEnv>> made =
      VectorEnv::Create("InvertedPendulum", 4, 1);
  ASSERT_TRUE(made.ok()) << made.status();
  VectorEnv& envs = **made;
  ASSERT_TRUE(envs.Reset().ok());
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> action(-3.0, 3.0);
  int episodes = 0;
  for (int step = 0; step < 500 && episodes < 6; ++step) {
    std::vector<double> actions(4);
    for (double& a : actions) a = action(rng);
    ASSERT_TRUE(envs.Step(actions).ok());
    for (const FinishedEpisode& episode : envs.finished()) {
      ++episodes;
      const int i = episode.env_index;
      EXPECT_TRUE(envs.terminated()[i]);
      EXPECT_FALSE(episode.truncated);
      EXPECT_GE(episode.length, 1);
      EXPECT_DOUBLE_EQ(episode.episode_return, episode.length);
      // The pole had fallen past 0.2 rad; the new episode starts upright.
      EXPECT_GT(std::fabs(envs.final_observations()[4 * i + 1]), 0.2);
      EXPECT_LE(std::fabs(envs.observations()[4 * i + 1]), 0.01);
    }
  }
  EXPECT_GE(episodes, 6);
}

TEST(VectorEnvTest, SeededRunsRepeat) {
  std::vector<double> first, second;
  for (std::vector<double>* out : {&first, &second}) {
    auto envs = std::move(*VectorEnv::Create("Hopper", 3, 9));
    ASSERT_TRUE(envs->Reset().ok());
    for (int step = 0; step < 50; ++step) {
      ASSERT_TRUE(envs->Step(std::vector<double>(9, 0.3)).ok());
      out->insert(out->end(), envs->observations().begin(),
                  envs->observations().end());
    }
  }
  EXPECT_EQ(first, second);
}

TEST(VectorEnvTest, ErrorsNameTheEnvironment) {
  auto envs = std::move(*VectorEnv::Create("Hopper", 2, 0));
  ASSERT_TRUE(envs->Reset().ok());
  EXPECT_THAT(envs->Step(std::vector<double>(5, 0.0)).message(),
              HasSubstr("actions hold 5 values, expected 2 x 3"));
  std::vector<double> actions(6, 0.0);
  actions[4] = std::nan("");
  const absl::Status status = envs->Step(actions);
  EXPECT_THAT(status.message(), HasSubstr("env 1: "));
  EXPECT_FALSE(VectorEnv::Create("Hopper", 0, 0).ok());
}

}  // namespace
}  // namespace vantage
