#include "common/env/frame_stack.h"

#include <memory>
#include <random>
#include <string>
#include <vector>

#include "absl/types/span.h"
#include "actor/envs/env_registry.h"
#include "common/util/state_bytes.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace vantage {
namespace {

using ::testing::HasSubstr;

std::unique_ptr<Environment> Make(const std::string& name, int64_t frames) {
  EnvOptions options;
  options.frame_stack = frames;
  absl::StatusOr<std::unique_ptr<Environment>> env =
      MakeEnvironment(name, options);
  EXPECT_TRUE(env.ok()) << env.status();
  return env.ok() ? *std::move(env) : nullptr;
}

TEST(FrameStackTest, SpecsGrowAlongTheChannels) {
  std::unique_ptr<Environment> breakout = Make("MinAtarBreakout", 4);
  const EnvSpec& spec = breakout->spec();
  EXPECT_EQ(spec.name, "MinAtarBreakout");
  EXPECT_EQ(spec.observation_size, 1600);
  EXPECT_EQ(spec.observation_shape, (std::vector<int64_t>{16, 10, 10}));
  EXPECT_EQ(spec.observation_high, 1);
  EXPECT_EQ(spec.action_size, 6);
  EXPECT_TRUE(CheckObservationLayout(spec).ok());
  // Vectors are joined end to end.
  std::unique_ptr<Environment> pendulum = Make("InvertedPendulum", 3);
  EXPECT_EQ(pendulum->spec().observation_size, 12);
  EXPECT_TRUE(pendulum->spec().observation_shape.empty());
  // One frame is the environment as it is.
  EXPECT_EQ(StackedSpec(spec, 1).observation_size, spec.observation_size);
  EXPECT_EQ(Make("MinAtarBreakout", 1)->spec().observation_size, 400);
}

TEST(FrameStackTest, OnlyTwoToSixteenFramesStack) {
  for (int64_t frames : {0, -1, 17}) {
    EnvOptions options;
    options.frame_stack = frames;
    EXPECT_THAT(MakeEnvironment("MinAtarBreakout", options).status().message(),
                HasSubstr("frames, expected 2..16 (1: no stacking)"))
        << frames;
  }
}

// Each stacked observation is the last four plain ones, oldest first, the
// first one repeated after a reset; a step the environment refuses
// changes nothing.
TEST(FrameStackTest, ObservationsAreTheLastFramesOldestFirst) {
  constexpr int64_t kFrames = 4;
  std::unique_ptr<Environment> plain = Make("MinAtarBreakout", 1);
  std::unique_ptr<Environment> stacked = Make("MinAtarBreakout", kFrames);
  const size_t size = 400;
  std::vector<double> one(size), all(kFrames * size);
  std::vector<std::vector<double>> seen;
  auto expect_last_frames = [&](int step) {
    for (int64_t f = 0; f < kFrames; ++f) {
      const int64_t index =
          std::max<int64_t>(0, static_cast<int64_t>(seen.size()) - kFrames + f);
      const std::vector<double> part(all.begin() + f * size,
                                     all.begin() + (f + 1) * size);
      ASSERT_EQ(part, seen[index]) << "step " << step << " frame " << f;
    }
  };
  ASSERT_TRUE(plain->Reset(7, absl::MakeSpan(one)).ok());
  ASSERT_TRUE(stacked->Reset(7, absl::MakeSpan(all)).ok());
  seen.push_back(one);
  expect_last_frames(0);
  std::mt19937_64 rng(3);
  bool moved = false;
  for (int step = 1; step <= 60; ++step) {
    const double action = static_cast<double>(rng() % 6);
    if (step == 5) {
      const double bad = 9;
      EXPECT_FALSE(stacked->Step({&bad, 1}, absl::MakeSpan(all)).ok());
    }
    absl::StatusOr<StepResult> a =
        plain->Step({&action, 1}, absl::MakeSpan(one));
    absl::StatusOr<StepResult> b =
        stacked->Step({&action, 1}, absl::MakeSpan(all));
    ASSERT_TRUE(a.ok() && b.ok());
    EXPECT_EQ(a->reward, b->reward);
    EXPECT_EQ(a->terminated, b->terminated);
    moved = moved || one != seen.back();
    seen.push_back(one);
    expect_last_frames(step);
    if (a->terminated || a->truncated) break;
  }
  EXPECT_TRUE(moved);
  // A buffer of the plain size is refused.
  EXPECT_THAT(stacked->Reset(1, absl::MakeSpan(one)).message(),
              HasSubstr("observation buffer holds 400 values, expected 1600"));
}

TEST(FrameStackTest, StatesRestoreTheHistoryAndHostileOnesChangeNothing) {
  std::unique_ptr<Environment> env = Make("MinAtarBreakout", 3);
  std::vector<double> obs(1200), replay(1200), after(1200);
  ASSERT_TRUE(env->Reset(11, absl::MakeSpan(obs)).ok());
  const double left = 1, right = 3;
  for (int i = 0; i < 4; ++i) {
    ASSERT_TRUE(
        env->Step({i % 2 ? &left : &right, 1}, absl::MakeSpan(obs)).ok());
  }
  absl::StatusOr<std::string> saved = env->SaveState();
  ASSERT_TRUE(saved.ok()) << saved.status();
  ASSERT_TRUE(env->Step({&left, 1}, absl::MakeSpan(obs)).ok());
  ASSERT_TRUE(env->Step({&left, 1}, absl::MakeSpan(after)).ok());
  // Another environment, restored, continues exactly.
  std::unique_ptr<Environment> other = Make("MinAtarBreakout", 3);
  ASSERT_TRUE(other->RestoreState(*saved).ok());
  ASSERT_TRUE(other->Step({&left, 1}, absl::MakeSpan(replay)).ok());
  EXPECT_EQ(replay, obs);
  ASSERT_TRUE(other->Step({&left, 1}, absl::MakeSpan(replay)).ok());
  EXPECT_EQ(replay, after);

  // Another stack depth, and a history no observation can have.
  std::unique_ptr<Environment> deeper = Make("MinAtarBreakout", 4);
  EXPECT_THAT(deeper->RestoreState(*saved).message(), HasSubstr("frames"));
  absl::StatusOr<std::string> inner =
      static_cast<FrameStack&>(*other).inner().SaveState();
  ASSERT_TRUE(inner.ok());
  StateWriter writer("frame_stack", 1);
  writer.PutBytes("MinAtarBreakout");
  writer.PutI64(3);
  writer.PutI64(400);
  std::vector<double> history(1200, 0.0);
  history[17] = 2;  // MinAtar's channels hold 0 or 1
  writer.PutDoubles(history);
  writer.PutBytes(*inner);
  const std::string hostile = std::move(writer).Finish();
  ASSERT_TRUE(other->RestoreState(*saved).ok());
  EXPECT_THAT(other->RestoreState(hostile).message(),
              HasSubstr("history holds a value no observation can have"));
  ASSERT_TRUE(other->Step({&left, 1}, absl::MakeSpan(replay)).ok());
  EXPECT_EQ(replay, obs);
}

}  // namespace
}  // namespace vantage
