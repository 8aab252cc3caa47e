#include "learner/algorithms/algorithm.h"

#include <google/protobuf/descriptor.h>

#include <cmath>
#include <set>
#include <string>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "learner/algorithms/a2c/a2c_config.h"
#include "learner/algorithms/ppo/ppo_config.h"
#include "learner/algorithms/trpo/trpo_config.h"
#include "proto/run_config.pb.h"
#include "proto/settings_table.h"

namespace vantage {
namespace {

using ::testing::HasSubstr;

// Adding an algorithm is one folder, one registry line and its section in
// the run config's oneof; the two lists must name the same algorithms.
TEST(AlgorithmTest, EveryAlgorithmHasItsRunConfigSection) {
  const auto* oneof = pb::RunConfig::descriptor()->FindOneofByName("algorithm");
  ASSERT_NE(oneof, nullptr);
  std::set<std::string> sections;
  for (int i = 0; i < oneof->field_count(); ++i) {
    sections.insert(oneof->field(i)->name());
  }
  const std::vector<std::string> names = AlgorithmNames();
  EXPECT_EQ(sections, std::set<std::string>(names.begin(), names.end()));
  for (const std::string& name : names) {
    pb::RunConfig run;
    ASSERT_TRUE(SelectAlgorithm(name, run).ok()) << name;
    EXPECT_EQ(AlgorithmNameOf(run), name);
  }
}

TEST(AlgorithmTest, UnknownNamesListTheValidOnes) {
  pb::RunConfig run;
  const absl::Status status = SelectAlgorithm("sac", run);
  EXPECT_THAT(std::string(status.message()),
              HasSubstr("unknown algorithm 'sac'; available: a2c, ppo, trpo"));
  // Names of the run config's other message fields are no algorithms.
  EXPECT_FALSE(SelectAlgorithm("training", run).ok());
  EXPECT_EQ(AlgorithmNameOf(run), "ppo");
}

// An empty section means the struct defaults, and writing a config back
// gives every field, which reads back as the same config.
TEST(AlgorithmTest, AbsentSettingsAreTheStructDefaults) {
  pb::RunConfig run;
  AlgorithmConfig ppo = AlgorithmConfigOf(run);
  EXPECT_EQ(ppo.name, "ppo");
  EXPECT_EQ(ppo.Get<PpoConfig>().minibatches, PpoConfig().minibatches);
  ASSERT_TRUE(SelectAlgorithm("a2c", run).ok());
  run.mutable_a2c()->set_learning_rate(1e-3);
  AlgorithmConfig a2c = AlgorithmConfigOf(run);
  EXPECT_EQ(a2c.name, "a2c");
  EXPECT_EQ(a2c.Get<A2cConfig>().n, A2cConfig().n);
  EXPECT_EQ(a2c.Get<A2cConfig>().learning_rate, 1e-3);
  pb::RunConfig written;
  SetAlgorithmSettings(a2c, written);
  EXPECT_TRUE(written.a2c().has_n());
  EXPECT_TRUE(written.a2c().has_entropy_coef());
  const AlgorithmConfig again = AlgorithmConfigOf(written);
  EXPECT_EQ(again.Get<A2cConfig>().n, a2c.Get<A2cConfig>().n);
  EXPECT_EQ(again.Get<A2cConfig>().learning_rate, 1e-3);

  run.Clear();
  ASSERT_TRUE(SelectAlgorithm("trpo", run).ok());
  run.mutable_trpo()->set_max_kl(0.05);
  const AlgorithmConfig trpo = AlgorithmConfigOf(run);
  EXPECT_EQ(trpo.Get<TrpoConfig>().max_kl, 0.05);
  EXPECT_EQ(trpo.Get<TrpoConfig>().value_learning_rate,
            TrpoConfig().value_learning_rate);
}

TEST(AlgorithmTest, RunDefaultsAreTheBaselines) {
  AlgorithmConfig config;
  EXPECT_EQ(RunDefaultsOf(config).horizon, 2048);
  EXPECT_EQ(RunDefaultsOf(config).gae_lambda, 0.95);
  EXPECT_FALSE(RunDefaultsOf(config).fixes_horizon);
  config.name = "a2c";
  config.Mutable<A2cConfig>().n = 7;
  EXPECT_EQ(RunDefaultsOf(config).horizon, 35);
  EXPECT_EQ(RunDefaultsOf(config).gae_lambda, 1.0);
  EXPECT_TRUE(RunDefaultsOf(config).fixes_horizon);
  config.name = "trpo";
  EXPECT_EQ(RunDefaultsOf(config).horizon, 1024);
  EXPECT_EQ(RunDefaultsOf(config).gae_lambda, 0.98);
}

TEST(AlgorithmTest, ValidationNamesTheField) {
  AlgorithmConfig config;
  config.Mutable<PpoConfig>().epochs = 0;
  EXPECT_EQ(config.Validate().message(), "ppo.epochs must be >= 1");
  config.name = "trpo";  // the ppo settings are not its business
  EXPECT_TRUE(config.Validate().ok());
  config.Mutable<TrpoConfig>().max_kl = -1;
  EXPECT_EQ(config.Validate().message(), "trpo.max_kl must be > 0");
}

// Each setting is one row of its algorithm's table: every field of every
// algorithm's section is written, and each range names its field and
// holds at its ends (NaN is in none).
TEST(AlgorithmTest, EverySettingIsWrittenAndRangeChecked) {
  for (const std::string& name : AlgorithmNames()) {
    pb::RunConfig run;
    ASSERT_TRUE(SelectAlgorithm(name, run).ok());
    pb::RunConfig written;
    SetAlgorithmSettings(AlgorithmConfigOf(run), written);
    const auto* section = pb::RunConfig::descriptor()->FindFieldByName(name);
    const google::protobuf::Message& settings =
        written.GetReflection()->GetMessage(written, section);
    std::vector<const google::protobuf::FieldDescriptor*> set;
    settings.GetReflection()->ListFields(settings, &set);
    EXPECT_EQ(static_cast<int>(set.size()),
              settings.GetDescriptor()->field_count())
        << name << " leaves fields unwritten";
  }
  AlgorithmConfig config;
  config.Mutable<PpoConfig>().clip = 1;
  EXPECT_EQ(config.Validate().message(), "ppo.clip must be in (0, 1)");
  config.Mutable<PpoConfig>().clip = 0.999;
  EXPECT_TRUE(config.Validate().ok());
  config.Mutable<PpoConfig>().entropy_coef = std::nan("");
  EXPECT_EQ(config.Validate().message(), "ppo.entropy_coef must be >= 0");
  config.name = "a2c";
  config.Mutable<A2cConfig>().rmsprop_alpha = 0;
  EXPECT_EQ(config.Validate().message(), "a2c.rmsprop_alpha must be in (0, 1)");
  config.Mutable<A2cConfig>().rmsprop_alpha = 0.5;
  config.Mutable<A2cConfig>().rmsprop = "adam";
  EXPECT_THAT(std::string(config.Validate().message()),
              HasSubstr("a2c.rmsprop must be tensorflow or pytorch"));
  config.name = "trpo";
  config.Mutable<TrpoConfig>().cg_damping = -0.1;
  EXPECT_EQ(config.Validate().message(), "trpo.cg_damping must be >= 0");
}

// A table that names a field its settings lack, or puts a range on a
// setting that is not a number, is a bug caught at its first use.
TEST(AlgorithmDeathTest, ATableRowMustFitItsSettings) {
  using Table = SettingsTable<PpoConfig, pb::PpoSettings>;
  EXPECT_DEATH(Table("ppo", {{"no_such_field", &PpoConfig::clip}}),
               "ppo.no_such_field settings have no such field");
  EXPECT_DEATH(Table("ppo", {{"normalize_advantages",
                              &PpoConfig::normalize_advantages, AtLeast(0)}}),
               "ppo.normalize_advantages is not a number");
  Table numbers("ppo",
                {{"clip", &PpoConfig::clip, Above(0), Below(1)},
                 {"normalize_advantages", &PpoConfig::normalize_advantages}});
  PpoConfig ppo;
  EXPECT_TRUE(numbers.Validate(ppo).ok());
}

}  // namespace
}  // namespace vantage
