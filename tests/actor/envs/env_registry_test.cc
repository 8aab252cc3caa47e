#include "actor/envs/env_registry.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "actor/envs/mujoco/mujoco_model.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/fakes/box_model.h"
#include "tests/fakes/random_discrete_action.h"

namespace vantage {
namespace {

using ::testing::HasSubstr;

std::unique_ptr<Environment> Make(const std::string& name) {
  absl::StatusOr<std::unique_ptr<Environment>> env = MakeEnvironment(name);
  EXPECT_TRUE(env.ok()) << env.status();
  return env.ok() ? std::move(*env) : nullptr;
}

std::vector<double> RandomAction(const Environment& env, std::mt19937_64& rng) {
  const EnvSpec& spec = env.spec();
  if (spec.discrete) return RandomDiscreteAction(env, rng);
  std::vector<double> action(spec.action_size);
  for (int64_t i = 0; i < spec.action_size; ++i) {
    action[i] = std::uniform_real_distribution<double>(
        spec.action_low[i], spec.action_high[i])(rng);
  }
  return action;
}

// Runs one episode (at most `max_steps`) and returns every observation.
std::vector<std::vector<double>> Episode(Environment& env, uint64_t seed,
                                         int max_steps, StepResult* last) {
  std::mt19937_64 rng(seed);
  std::vector<double> observation(env.spec().observation_size);
  EXPECT_TRUE(env.Reset(seed, absl::MakeSpan(observation)).ok());
  std::vector<std::vector<double>> seen = {observation};
  for (int t = 0; t < max_steps; ++t) {
    absl::StatusOr<StepResult> result =
        env.Step(RandomAction(env, rng), absl::MakeSpan(observation));
    EXPECT_TRUE(result.ok()) << result.status();
    if (!result.ok()) break;
    seen.push_back(observation);
    *last = *result;
    if (result->terminated || result->truncated) break;
  }
  return seen;
}

TEST(EnvRegistryTest, SpecsMatchTheGymnasiumTasks) {
  const std::map<std::string, std::pair<int, int>> expected = {
      {"HalfCheetah", {17, 6}},
      {"Hopper", {11, 3}},
      {"Walker2d", {17, 6}},
      {"Ant", {27, 8}},
      {"InvertedPendulum", {4, 1}},
      {"InvertedDoublePendulum", {11, 1}},
      {"SparseHalfCheetah", {17, 6}},
      {"Humanoid", {376, 17}},
      {"PointMaze", {4, 2}},
      {"TwoDMaze", {2, 2}},
      {"Ex2SparseHalfCheetah", {20, 6}},
      {"BulletHopper", {11, 3}},
      {"BipedWalkFlat", {29, 11}},
      {"BipedWalkIncline", {29, 11}},
      {"TerrainBipedFlat", {54, 11}},
      {"TerrainBipedIncline", {54, 11}}};
  for (const auto& [name, sizes] : expected) {
    const auto env = Make(name);
    ASSERT_NE(env, nullptr);
    EXPECT_EQ(env->spec().observation_size, sizes.first) << name;
    EXPECT_EQ(env->spec().action_size, sizes.second) << name;
    const std::map<std::string, int64_t> short_episodes = {
        {"PointMaze", 500},
        {"TwoDMaze", 200},
        {"Ex2SparseHalfCheetah", 500},
        {"TerrainBipedFlat", 256},
        {"TerrainBipedIncline", 256}};
    EXPECT_EQ(env->spec().max_episode_steps,
              short_episodes.count(name) > 0 ? short_episodes.at(name) : 1000)
        << name;
  }
}

TEST(EnvRegistryTest, EveryRegisteredEnvStepsWithFiniteValues) {
  for (const std::string& name : RegisteredEnvironments()) {
    const auto env = Make(name);
    ASSERT_NE(env, nullptr) << name;
    const EnvSpec& spec = env->spec();
    EXPECT_EQ(spec.action_low.size(),
              spec.discrete ? 0u : static_cast<size_t>(spec.action_size));
    EXPECT_GT(spec.control_dt, 0.0);
    EXPECT_TRUE(CheckObservationLayout(spec).ok())
        << CheckObservationLayout(spec);
    StepResult last;
    for (const auto& observation : Episode(*env, 3, 200, &last)) {
      ASSERT_EQ(observation.size(), static_cast<size_t>(spec.observation_size));
      for (double value : observation) {
        ASSERT_TRUE(std::isfinite(value)) << name;
        // Byte observations are what a uint8 holds exactly.
        if (spec.byte_observations()) {
          ASSERT_EQ(value, std::floor(value)) << name;
          ASSERT_GE(value, 0) << name;
          ASSERT_LE(value, spec.observation_high) << name;
        }
      }
    }
    EXPECT_TRUE(std::isfinite(last.reward)) << name;
  }
}

TEST(EnvRegistryTest, SameSeedSameEpisodeOtherSeedOther) {
  for (const std::string& name : RegisteredEnvironments()) {
    const auto a = Make(name);
    const auto b = Make(name);
    StepResult last;
    const auto first = Episode(*a, 11, 50, &last);
    EXPECT_EQ(first, Episode(*b, 11, 50, &last)) << name;
    EXPECT_NE(first, Episode(*b, 12, 50, &last)) << name;
  }
}

TEST(EnvRegistryTest, TimeLimitTruncatesWithTheFinalObservation) {
  const auto env = Make("HalfCheetah");  // never terminates
  StepResult last;
  const auto seen = Episode(*env, 5, 2000, &last);
  EXPECT_EQ(seen.size(), 1001u);
  EXPECT_TRUE(last.truncated);
  EXPECT_FALSE(last.terminated);
  std::vector<double> observation(17);
  const std::vector<double> action(6, 0.0);
  absl::StatusOr<StepResult> after =
      env->Step(action, absl::MakeSpan(observation));
  EXPECT_EQ(after.status().code(), absl::StatusCode::kFailedPrecondition);
  // The observation Step wrote with truncated set is the final one; the
  // next episode starts elsewhere.
  EXPECT_TRUE(env->Reset(6, absl::MakeSpan(observation)).ok());
  EXPECT_NE(observation, seen.back());
}

TEST(EnvRegistryTest, FallingBodiesTerminate) {
  for (const char* name :
       {"Hopper", "Walker2d", "InvertedPendulum", "InvertedDoublePendulum",
        "BulletHopper", "BipedWalkFlat", "BipedWalkIncline"}) {
    const auto env = Make(name);
    std::vector<double> observation(env->spec().observation_size);
    ASSERT_TRUE(env->Reset(1, absl::MakeSpan(observation)).ok());
    // Full torque on every actuator tips every one of them over.
    const std::vector<double> action(env->spec().action_size, 1.0);
    int steps = 0;
    StepResult result;
    while (steps < 1000) {
      absl::StatusOr<StepResult> stepped =
          env->Step(action, absl::MakeSpan(observation));
      ASSERT_TRUE(stepped.ok()) << stepped.status();
      result = *stepped;
      ++steps;
      if (result.terminated || result.truncated) break;
    }
    EXPECT_TRUE(result.terminated) << name;
    EXPECT_FALSE(result.truncated) << name;
    EXPECT_LT(steps, 1000) << name;
  }
}

// The Ant's height rule: random flailing bounces the torso out of (0.2, 1)
// within a few hundred steps.
TEST(EnvRegistryTest, AntLeavingItsHeightRangeTerminates) {
  const auto env = Make("Ant");
  int terminated = 0;
  for (uint64_t seed = 0; seed < 5; ++seed) {
    StepResult last;
    const auto seen = Episode(*env, seed, 1000, &last);
    if (last.terminated) {
      ++terminated;
      EXPECT_LT(seen.size(), 1001u);
    }
  }
  EXPECT_GE(terminated, 3);
}

// Sparse tasks: a random policy earns nothing, a purposeful one does.
TEST(EnvRegistryTest, PointMazeRewardsOnlyTheGoal) {
  const auto env = Make("PointMaze");
  std::vector<double> observation(4);
  int random_successes = 0;
  for (uint64_t episode = 0; episode < 50; ++episode) {
    StepResult last;
    Episode(*env, episode, 600, &last);
    random_successes += last.terminated;
  }
  EXPECT_EQ(random_successes, 0);
  // Steering through the waypoints round the wall reaches the goal.
  ASSERT_TRUE(env->Reset(0, absl::MakeSpan(observation)).ok());
  const double waypoints[3][2] = {{1.5, -1.5}, {1.5, 1.5}, {-1.5, 1.5}};
  int target = 0;
  double total = 0.0;
  StepResult result;
  for (int t = 0; t < 500; ++t) {
    const double dx = waypoints[target][0] - observation[0];
    const double dy = waypoints[target][1] - observation[1];
    if (target < 2 && std::hypot(dx, dy) < 0.3) ++target;
    const std::vector<double> action = {3 * dx - observation[2],
                                        3 * dy - observation[3]};
    result = *env->Step(action, absl::MakeSpan(observation));
    total += result.reward;
    if (result.terminated || result.truncated) break;
  }
  EXPECT_TRUE(result.terminated);
  EXPECT_EQ(total, 1.0);
}

// EX2's maze: -1 per step until the point is in the target's pocket on
// the far side of the wall, where the reward rises towards 0 at the target.
TEST(EnvRegistryTest, TwoDMazeRewardsThePocketBeyondTheWall) {
  const auto env = Make("TwoDMaze");
  std::vector<double> observation(2);
  ASSERT_TRUE(env->Reset(3, absl::MakeSpan(observation)).ok());
  EXPECT_NEAR(observation[0], -0.15, 0.011);
  EXPECT_NEAR(observation[1], -0.15, 0.011);
  // Straight at the target: the wall stops the point, every step pays -1.
  StepResult result;
  int steps = 0;
  while (!result.truncated) {
    result = *env->Step({1.0, 0.0}, absl::MakeSpan(observation));
    EXPECT_EQ(result.reward, -1.0);
    EXPECT_LT(observation[0], -0.04);
    ++steps;
  }
  EXPECT_EQ(steps, 200);
  // Over the top of the wall and down into the pocket.
  ASSERT_TRUE(env->Reset(3, absl::MakeSpan(observation)).ok());
  const double waypoints[3][2] = {{-0.15, 0.15}, {0.15, 0.15}, {0.15, -0.15}};
  int target = 0;
  double total = 0.0;
  result = StepResult();
  while (!result.truncated) {
    const double dx = waypoints[target][0] - observation[0];
    const double dy = waypoints[target][1] - observation[1];
    if (target < 2 && std::hypot(dx, dy) < 0.03) ++target;
    result = *env->Step(
        {std::clamp(20 * dx, -1.0, 1.0), std::clamp(20 * dy, -1.0, 1.0)},
        absl::MakeSpan(observation));
    total += result.reward;
  }
  EXPECT_FALSE(result.terminated);
  EXPECT_GT(result.reward, -0.1);  // within 2 cm (L1) of the target
  EXPECT_GT(total, -150.0);        // a wall-hugger's is -200
}

TEST(EnvRegistryTest, SparseHalfCheetahIsSilentNearTheStart) {
  const auto env = Make("SparseHalfCheetah");
  std::mt19937_64 rng(1);
  std::vector<double> observation(17);
  ASSERT_TRUE(env->Reset(1, absl::MakeSpan(observation)).ok());
  for (int t = 0; t < 200; ++t) {
    absl::StatusOr<StepResult> result =
        env->Step(RandomAction(*env, rng), absl::MakeSpan(observation));
    ASSERT_TRUE(result.ok());
    EXPECT_EQ(result->reward, 0.0);
  }
}

TEST(EnvRegistryTest, ActionsAreClippedToTheirBounds) {
  const auto clipped = Make("HalfCheetah");
  const auto bounded = Make("HalfCheetah");
  std::vector<double> a(17), b(17);
  ASSERT_TRUE(clipped->Reset(2, absl::MakeSpan(a)).ok());
  ASSERT_TRUE(bounded->Reset(2, absl::MakeSpan(b)).ok());
  const std::vector<double> huge = {5, -7, 100, -1e9, 2, 1.5};
  const std::vector<double> edge = {1, -1, 1, -1, 1, 1};
  absl::StatusOr<StepResult> x = clipped->Step(huge, absl::MakeSpan(a));
  absl::StatusOr<StepResult> y = bounded->Step(edge, absl::MakeSpan(b));
  ASSERT_TRUE(x.ok() && y.ok());
  EXPECT_EQ(a, b);
  EXPECT_EQ(x->reward, y->reward);  // the control cost uses clipped actions
}

TEST(EnvRegistryTest, BadActionsAreRefusedAndTheEpisodeGoesOn) {
  const auto env = Make("Hopper");
  std::vector<double> observation(11);
  ASSERT_TRUE(env->Reset(4, absl::MakeSpan(observation)).ok());
  const std::vector<double> before = observation;
  absl::StatusOr<StepResult> nan =
      env->Step({0.1, std::nan(""), 0.0}, absl::MakeSpan(observation));
  EXPECT_EQ(nan.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(nan.status().message(), HasSubstr("action[1] is not finite"));
  EXPECT_EQ(observation, before);
  absl::StatusOr<StepResult> short_action =
      env->Step({0.1, 0.2}, absl::MakeSpan(observation));
  EXPECT_THAT(short_action.status().message(),
              HasSubstr("action has 2 values, expected 3"));
  EXPECT_TRUE(env->Step({0.1, 0.2, 0.3}, absl::MakeSpan(observation)).ok());
}

TEST(EnvRegistryTest, UnknownNameListsTheRegisteredOnes) {
  absl::StatusOr<std::unique_ptr<Environment>> env =
      MakeEnvironment("HalfCheeta");
  ASSERT_FALSE(env.ok());
  EXPECT_THAT(env.status().message(), HasSubstr("unknown environment"));
  EXPECT_THAT(env.status().message(), HasSubstr("HalfCheetah, Hopper"));
  EXPECT_THAT(env.status().message(), HasSubstr("mjcf:"));
}

// A variant is the same task with other options: SparseHalfCheetah is
// HalfCheetah with the sparse threshold set, step for step, and the spec is
// named with its options in one spelling.
TEST(EnvOptionsTest, AVariantIsTheTaskWithOptions) {
  std::unique_ptr<Environment> alias = Make("SparseHalfCheetah");
  std::unique_ptr<Environment> optioned =
      Make("HalfCheetah: sparse_x_threshold=5");
  ASSERT_NE(alias, nullptr);
  ASSERT_NE(optioned, nullptr);
  EXPECT_EQ(optioned->spec().name, "HalfCheetah:sparse_x_threshold=5");
  StepResult last;
  EXPECT_EQ(Episode(*alias, 3, 200, &last), Episode(*optioned, 3, 200, &last));
  std::unique_ptr<Environment> two =
      Make("Hopper:max_episode_steps=20,ctrl_cost=0.5");
  ASSERT_NE(two, nullptr);
  EXPECT_EQ(two->spec().name, "Hopper:ctrl_cost=0.5,max_episode_steps=20");
  EXPECT_EQ(two->spec().max_episode_steps, 20);
  // The option changes the task: a dense HalfCheetah pays for speed where
  // the sparse one pays nothing near the start.
  std::unique_ptr<Environment> dense = Make("HalfCheetah");
  std::vector<double> observation(17);
  ASSERT_TRUE(dense->Reset(1, absl::MakeSpan(observation)).ok());
  ASSERT_TRUE(optioned->Reset(1, absl::MakeSpan(observation)).ok());
  const std::vector<double> push(6, 1.0);
  absl::StatusOr<StepResult> paid =
      dense->Step(push, absl::MakeSpan(observation));
  absl::StatusOr<StepResult> silent =
      optioned->Step(push, absl::MakeSpan(observation));
  ASSERT_TRUE(paid.ok() && silent.ok());
  EXPECT_NE(paid->reward, 0.0);
  EXPECT_EQ(silent->reward, 0.0);
}

// hide_velocities: the same task observed through its positions alone.
TEST(EnvOptionsTest, HiddenVelocitiesLeaveThePositions) {
  std::unique_ptr<Environment> full = Make("HalfCheetah");
  std::unique_ptr<Environment> hidden =
      Make("HalfCheetah:hide_velocities=true");
  ASSERT_NE(full, nullptr);
  ASSERT_NE(hidden, nullptr);
  ASSERT_EQ(full->spec().observation_size, 17);
  ASSERT_EQ(hidden->spec().observation_size, 8);  // qpos less the x
  std::vector<double> seen(17), positions(8);
  ASSERT_TRUE(full->Reset(4, absl::MakeSpan(seen)).ok());
  ASSERT_TRUE(hidden->Reset(4, absl::MakeSpan(positions)).ok());
  const std::vector<double> push(6, 0.5);
  for (int t = 0; t < 20; ++t) {
    EXPECT_EQ(positions, std::vector<double>(seen.begin(), seen.begin() + 8))
        << "step " << t;
    absl::StatusOr<StepResult> a = full->Step(push, absl::MakeSpan(seen));
    absl::StatusOr<StepResult> b =
        hidden->Step(push, absl::MakeSpan(positions));
    ASSERT_TRUE(a.ok() && b.ok());
    EXPECT_EQ(a->reward, b->reward);
  }
}

TEST(EnvOptionsTest, BadOptionsAreRefusedByName) {
  const std::pair<std::string, std::string> cases[] = {
      {"HalfCheetah:bogus=1",
       "HalfCheetah has no option 'bogus'; its options: frame_skip,"},
      {"Hopper:frame_skip=0", "frame_skip=0 is not at least 1"},
      {"Ant:ctrl_cost=nan", "ctrl_cost=nan is not a finite number"},
      {"Walker2d:frame_skip=2.5", "frame_skip=2.5 is not an integer"},
      {"Hopper:ctrl_cost", "'ctrl_cost' is no option"},
      {"Hopper:ctrl_cost=1,ctrl_cost=2", "ctrl_cost is given twice"},
      {"MinAtarBreakout:x=1",
       "MinAtarBreakout has no option 'x'; it takes none"},
  };
  for (const auto& [name, message] : cases) {
    absl::StatusOr<std::unique_ptr<Environment>> env = MakeEnvironment(name);
    ASSERT_FALSE(env.ok()) << name;
    EXPECT_TRUE(absl::IsInvalidArgument(env.status())) << env.status();
    EXPECT_THAT(std::string(env.status().message()), HasSubstr(message))
        << name;
  }
}

TEST(EnvOptionsTest, OptionsAreListedWithTheTasksDefaults) {
  std::map<std::string, std::string> defaults;
  for (const EnvOptionInfo& option :
       EnvironmentOptions("Ex2SparseHalfCheetah")) {
    defaults[option.name] = option.default_value;
    EXPECT_FALSE(option.help.empty()) << option.name;
  }
  EXPECT_EQ(defaults["frame_skip"], "1");
  EXPECT_EQ(defaults["max_episode_steps"], "500");
  EXPECT_EQ(defaults["sparse_either_way"], "true");
  EXPECT_TRUE(EnvironmentOptions("MinAtarBreakout").empty());
}

TEST(MujocoGuardTest, MujocoErrorsBecomeStatuses) {
  const absl::Status status = GuardMujoco([] { mju_error("boom"); });
  EXPECT_EQ(status.code(), absl::StatusCode::kInternal);
  EXPECT_THAT(status.message(), HasSubstr("boom"));
}

// ---------------------------------------------------------------------------
// mjcf:PATH

class MjcfEnvTest : public ::testing::Test {
 protected:
  std::string Write(const std::string& name, const std::string& xml) {
    const std::string path =
        absl::StrCat(::testing::TempDir(), "/vantage_mjcf_", name, ".xml");
    std::ofstream(path) << xml;
    return path;
  }
};

// A sliding, hopping box with a motor on each axis.
TEST_F(MjcfEnvTest, CustomBlockDefinesTheTask) {
  const std::string path = Write("good", BoxModel(R"xml(
    <text name="vantage_forward_body" data="box"/>
    <numeric name="vantage_forward_weight" data="2"/>
    <numeric name="vantage_ctrl_cost" data="0.5"/>
    <numeric name="vantage_alive_bonus" data="1"/>
    <numeric name="vantage_healthy_z" data="0.05 1.0"/>
    <numeric name="vantage_frame_skip" data="2"/>
    <numeric name="vantage_max_steps" data="50"/>)xml"));
  const auto env = Make("mjcf:" + path);
  ASSERT_NE(env, nullptr);
  const EnvSpec& spec = env->spec();
  EXPECT_EQ(spec.observation_size, 4);  // qpos 2 + qvel 2
  EXPECT_EQ(spec.action_size, 2);
  EXPECT_EQ(spec.max_episode_steps, 50);
  EXPECT_DOUBLE_EQ(spec.control_dt, 0.02);
  std::vector<double> observation(4);
  ASSERT_TRUE(env->Reset(0, absl::MakeSpan(observation)).ok());
  // Pushing forward only: reward = 2 * (dx / dt) + 1 - 0.5 * 1^2.
  const double x_before = observation[0];
  absl::StatusOr<StepResult> step =
      env->Step({1.0, 0.0}, absl::MakeSpan(observation));
  ASSERT_TRUE(step.ok()) << step.status();
  const double velocity = (observation[0] - x_before) / 0.02;
  EXPECT_GT(velocity, 0.0);
  EXPECT_NEAR(step->reward, 2.0 * velocity + 1.0 - 0.5, 1e-9);
  // Full upward thrust lifts the box above 1.0: unhealthy, terminated.
  bool terminated = false;
  for (int t = 0; t < 49 && !terminated; ++t) {
    absl::StatusOr<StepResult> up =
        env->Step({0.0, 1.0}, absl::MakeSpan(observation));
    ASSERT_TRUE(up.ok());
    terminated = up->terminated;
  }
  EXPECT_TRUE(terminated);
}

TEST_F(MjcfEnvTest, BadCustomEntriesAreNamed) {
  const std::map<std::string, std::string> cases = {
      {R"(<numeric name="vantage_speed" data="1"/>)", "'vantage_speed'"},
      {R"(<numeric name="vantage_frame_skip" data="0.5"/>)",
       "'vantage_frame_skip' needs a whole number"},
      {R"(<numeric name="vantage_ctrl_cost" data="-1"/>)",
       "'vantage_ctrl_cost' must be >= 0"},
      {R"(<numeric name="vantage_healthy_z" data="1"/>)",
       "'vantage_healthy_z' needs two numbers"},
      {R"(<text name="vantage_forward_body" data="wheel"/>)",
       "names body 'wheel'"},
      {R"(<numeric name="vantage_healthy_z" data="0 1"/>)",
       "needs vantage_forward_body"},
      // Whole numbers beyond the setting's type: converting them was
      // undefined behaviour (found by tests/fuzz/mjcf_fuzzer) or wrapped
      // around (4294967297 frames became 1).
      {R"(<numeric name="vantage_max_steps" data="922337203685477580850"/>)",
       "'vantage_max_steps' needs a whole number in [1, 9007199254740992]"},
      {R"(<numeric name="vantage_frame_skip" data="4294967297"/>)",
       "'vantage_frame_skip' needs a whole number in [1, 2147483647]"},
  };
  int i = 0;
  for (const auto& [custom, message] : cases) {
    const std::string path = Write(absl::StrCat("bad", i++), BoxModel(custom));
    absl::StatusOr<std::unique_ptr<Environment>> env =
        MakeEnvironment("mjcf:" + path);
    ASSERT_FALSE(env.ok()) << custom;
    EXPECT_EQ(env.status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_THAT(env.status().message(), HasSubstr(message)) << custom;
  }
}

TEST_F(MjcfEnvTest, BrokenOrMissingModelsAreErrors) {
  const std::string broken = Write("broken", "<mujoco><worldbody><body>");
  absl::StatusOr<std::unique_ptr<Environment>> env =
      MakeEnvironment("mjcf:" + broken);
  ASSERT_FALSE(env.ok());
  EXPECT_THAT(env.status().message(), HasSubstr("cannot load MJCF"));
  env = MakeEnvironment("mjcf:/nonexistent/model.xml");
  ASSERT_FALSE(env.ok());
  EXPECT_THAT(env.status().message(), HasSubstr("/nonexistent/model.xml"));
  EXPECT_FALSE(MakeEnvironment("mjcf:").ok());
}

}  // namespace
}  // namespace vantage
