#include "deploy/run_config.h"

#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace vantage {
namespace {

using ::testing::HasSubstr;

absl::StatusOr<pb::RunConfig> Resolve(const std::string& json) {
  absl::StatusOr<pb::RunConfig> parsed = ParseRunConfigJson(json);
  EXPECT_TRUE(parsed.ok()) << parsed.status();
  if (!parsed.ok()) return parsed.status();
  return ResolveRunConfig(*parsed);
}

TEST(RunConfigTest, DistributedBatchIsActorsTimesEnvsPerActor) {
  absl::StatusOr<pb::RunConfig> config =
      Resolve(R"({"actors": 3, "envs_per_actor": 4})");
  ASSERT_TRUE(config.ok()) << config.status();
  EXPECT_EQ(config->envs(), 12);
}

// actors x envs_per_actor used to overflow an int32 (undefined behaviour,
// found by tests/fuzz/run_config_fuzzer's UBSan build).
TEST(RunConfigTest, TooManyEnvsPerActorAreRefused) {
  for (const std::string& json :
       {std::string(R"({"envs_per_actor": 2147483647})"),
        std::string(R"({"actors": 256, "envs_per_actor": 4097})")}) {
    const absl::Status status = Resolve(json).status();
    EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument) << json;
    EXPECT_THAT(std::string(status.message()),
                HasSubstr("--envs_per_actor must be in [1, 4096]"))
        << json;
  }
  const absl::Status status =
      Resolve(R"({"actors": 256, "envs_per_actor": 4096})").status();
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(status.message()),
              HasSubstr("--envs_per_actor makes --actors x --envs_per_actor = "
                        "1048576 streams, more than 4096"));
}

}  // namespace
}  // namespace vantage
