#include <string>

#include "absl/strings/str_cat.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/deploy/cli/run_vantage.h"

namespace vantage {
namespace {

using ::testing::HasSubstr;

std::string ResultLine(const std::string& out) {
  const size_t at = out.rfind("RESULT rollout");
  return at == std::string::npos ? "" : out.substr(at);
}

TEST(EnvsCommandTest, ListsEveryTaskWithItsShapes) {
  const Outcome outcome = RunVantage("envs");
  ASSERT_EQ(outcome.exit_code, 0) << outcome.err;
  EXPECT_THAT(outcome.out, HasSubstr("HalfCheetah obs=[17] act=continuous:6"));
  EXPECT_THAT(outcome.out, HasSubstr("Ant obs=[27] act=continuous:8"));
  EXPECT_THAT(outcome.out,
              HasSubstr("InvertedPendulum obs=[4] act=continuous:1"));
  EXPECT_THAT(outcome.out,
              HasSubstr("MinAtarBreakout obs=[uint8 4x10x10] act=discrete:6"));
  EXPECT_THAT(outcome.out,
              HasSubstr("FirstPersonMaze obs=[uint8 3x42x42] act=discrete:4"));
}

TEST(RolloutCommandTest, SameSeedSameDigestOtherSeedOther) {
  const Outcome first =
      RunVantage("rollout --env=Hopper --episodes=3 --seed=7");
  const Outcome again =
      RunVantage("rollout --env=Hopper --episodes=3 --seed=7");
  const Outcome other =
      RunVantage("rollout --env=Hopper --episodes=3 --seed=8");
  ASSERT_EQ(first.exit_code, 0) << first.err;
  const std::string line = ResultLine(first.out);
  EXPECT_THAT(line, HasSubstr("env=Hopper obs_dim=11 act_dim=3 episodes=3"));
  EXPECT_THAT(line, HasSubstr("digest="));
  EXPECT_EQ(line, ResultLine(again.out));
  EXPECT_NE(line, ResultLine(other.out));
  // One line per episode before the RESULT line.
  EXPECT_THAT(first.out, HasSubstr("episode 2 return="));
}

TEST(RolloutCommandTest, BadFlagsAreClearErrors) {
  Outcome outcome = RunVantage("rollout --env=Nope --episodes=1");
  EXPECT_EQ(outcome.exit_code, 2);
  EXPECT_THAT(outcome.err, HasSubstr("unknown environment 'Nope'"));
  outcome = RunVantage("rollout --env=Hopper --episodes=0");
  EXPECT_EQ(outcome.exit_code, 2);
  EXPECT_THAT(outcome.err, HasSubstr("--episodes must be >= 1"));
  outcome = RunVantage("rollout");
  EXPECT_THAT(outcome.err, HasSubstr("--env=NAME is required"));
}

}  // namespace
}  // namespace vantage
