#include "actor/run_settings.h"

#include "gtest/gtest.h"

namespace vantage {
namespace {

TEST(RunSettingsTest, TheActorReadsWrappingAndNetworkFromTheRunConfig) {
  pb::RunConfig run;
  run.mutable_training()->set_frame_stack(4);
  run.mutable_training()->add_hidden(32);
  run.mutable_training()->add_hidden(16);
  run.mutable_training()->set_torso("minatar");
  EXPECT_EQ(EnvOptionsOf(run).frame_stack, 4);
  absl::StatusOr<NetworkConfig> network = PolicyNetworkOf(run);
  ASSERT_TRUE(network.ok()) << network.status();
  EXPECT_EQ(network->hidden, (std::vector<int64_t>{32, 16}));
  EXPECT_EQ(network->torso, Torso::kMinAtar);
}

// Configs written before frame stacking and torsos existed: no stacking,
// and the MLP every learner built then.
TEST(RunSettingsTest, OldConfigsMeanWhatTheyMeantThen) {
  pb::RunConfig old;
  old.mutable_training()->add_hidden(64);
  EXPECT_EQ(EnvOptionsOf(old).frame_stack, 1);
  absl::StatusOr<NetworkConfig> network = PolicyNetworkOf(old);
  ASSERT_TRUE(network.ok()) << network.status();
  EXPECT_EQ(network->torso, Torso::kMlp);
}

TEST(RunSettingsTest, AnUnknownTorsoIsNamed) {
  pb::RunConfig run;
  run.mutable_training()->set_torso("resnet");
  absl::StatusOr<NetworkConfig> network = PolicyNetworkOf(run);
  EXPECT_TRUE(absl::IsInvalidArgument(network.status()));
  EXPECT_NE(network.status().message().find("resnet"), std::string::npos)
      << network.status();
}

}  // namespace
}  // namespace vantage
