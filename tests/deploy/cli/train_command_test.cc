#include <string>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/deploy/cli/run_vantage.h"

namespace vantage {
namespace {

using ::testing::HasSubstr;

TEST(TrainCommandTest, ShortRunPrintsProgressAndResult) {
  const Outcome outcome =
      RunVantage("train --steps=256 --horizon=128 --envs=2 --seed=3");
  ASSERT_EQ(outcome.exit_code, 0) << outcome.err;
  EXPECT_THAT(outcome.out, HasSubstr("update   1 steps     256"));
  EXPECT_THAT(outcome.out, HasSubstr("RESULT train env=InvertedPendulum "
                                     "algo=ppo estimator=maxabs rho=0.4 "
                                     "steps=256"));
}

TEST(TrainCommandTest, BadFlagsAreOneLineErrors) {
  const std::pair<const char*, const char*> cases[] = {
      {"train --algo=sac", "unknown --algo='sac'; available: ppo"},
      {"train --mode=cluster", "unknown --mode='cluster'"},
      {"train --estimator=median", "unknown statistic 'median'"},
      {"train --rho=1.5", "rho must be in [0, 1]"},
      {"train --ensemble=1,x", "--ensemble entry 'x'"},
      {"train --steps=0", "must be >= 1"},
      {"train --env=Nope --steps=10", "unknown environment 'Nope'"},
  };
  for (const auto& [args, message] : cases) {
    const Outcome outcome = RunVantage(args);
    EXPECT_EQ(outcome.exit_code, 2) << args;
    EXPECT_THAT(outcome.err, HasSubstr(message)) << args;
  }
}

}  // namespace
}  // namespace vantage
