#include "common/advantage/advantage_config.h"

#include <cmath>
#include <limits>

#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace vantage {
namespace {

using ::testing::HasSubstr;

TEST(ParseStatisticTest, ParsesEveryName) {
  EXPECT_EQ(ParseStatistic("gae")->kind, StatisticKind::kGae);
  EXPECT_EQ(ParseStatistic("max")->kind, StatisticKind::kMax);
  EXPECT_EQ(ParseStatistic("min")->kind, StatisticKind::kMin);
  EXPECT_EQ(ParseStatistic("maxabs")->kind, StatisticKind::kMaxAbs);
  const absl::StatusOr<Statistic> order = ParseStatistic("order:3");
  ASSERT_TRUE(order.ok());
  EXPECT_EQ(order->kind, StatisticKind::kOrder);
  EXPECT_EQ(order->order, 3);
}

TEST(ParseStatisticTest, NameRoundTrips) {
  for (const char* name : {"gae", "max", "min", "maxabs", "order:12"}) {
    EXPECT_EQ(StatisticName(*ParseStatistic(name)), name);
  }
}

TEST(ParseStatisticTest, UnknownNameListsTheValidOnes) {
  const absl::StatusOr<Statistic> parsed = ParseStatistic("median");
  ASSERT_FALSE(parsed.ok());
  EXPECT_THAT(parsed.status().message(), HasSubstr("'median'"));
  EXPECT_THAT(parsed.status().message(),
              HasSubstr("gae, max, min, maxabs, order:D"));
}

TEST(ParseStatisticTest, RejectsBadRanks) {
  for (const char* name :
       {"order:", "order:0", "order:-1", "order:x", "order:2.5"}) {
    const absl::StatusOr<Statistic> parsed = ParseStatistic(name);
    ASSERT_FALSE(parsed.ok()) << name;
    EXPECT_THAT(parsed.status().message(), HasSubstr("integer >= 1")) << name;
  }
}

TEST(AdvantageConfigTest, DefaultsAreValid) {
  EXPECT_TRUE(AdvantageConfig().Validate().ok());
}

absl::Status ValidateWith(void (*edit)(AdvantageConfig&)) {
  AdvantageConfig config;
  edit(config);
  return config.Validate();
}

TEST(AdvantageConfigTest, GammaRange) {
  EXPECT_TRUE(ValidateWith([](AdvantageConfig& c) { c.gamma = 1.0; }).ok());
  for (double gamma : {0.0, -0.5, 1.01, std::nan("")}) {
    AdvantageConfig config;
    config.gamma = gamma;
    EXPECT_THAT(config.Validate().message(),
                HasSubstr("gamma must be in (0, 1]"))
        << gamma;
  }
}

TEST(AdvantageConfigTest, LambdaRange) {
  EXPECT_TRUE(ValidateWith([](AdvantageConfig& c) { c.lambda = 0.0; }).ok());
  EXPECT_TRUE(ValidateWith([](AdvantageConfig& c) { c.lambda = 1.0; }).ok());
  for (double lambda : {-0.1, 1.5, std::nan("")}) {
    AdvantageConfig config;
    config.lambda = lambda;
    EXPECT_THAT(config.Validate().message(),
                HasSubstr("lambda must be in [0, 1]"));
  }
}

TEST(AdvantageConfigTest, RhoRange) {
  EXPECT_TRUE(ValidateWith([](AdvantageConfig& c) { c.rho = 1.0; }).ok());
  for (double rho : {-0.01, 1.01, std::numeric_limits<double>::infinity()}) {
    AdvantageConfig config;
    config.rho = rho;
    EXPECT_THAT(config.Validate().message(),
                HasSubstr("rho must be in [0, 1]"));
  }
}

TEST(AdvantageConfigTest, EnsembleRules) {
  EXPECT_THAT(
      ValidateWith([](AdvantageConfig& c) { c.ensemble.clear(); }).message(),
      HasSubstr("at least one"));
  EXPECT_THAT(ValidateWith([](AdvantageConfig& c) {
                c.ensemble = {1, 0};
              }).message(),
              HasSubstr("positive step counts, got 0"));
  EXPECT_THAT(ValidateWith([](AdvantageConfig& c) {
                c.ensemble = {4, -2};
              }).message(),
              HasSubstr("got -2"));
  EXPECT_THAT(ValidateWith([](AdvantageConfig& c) {
                c.ensemble = {1, 16, 1};
              }).message(),
              HasSubstr("k=1 more than once"));
  EXPECT_TRUE(ValidateWith([](AdvantageConfig& c) {
                c.ensemble = {4096, 3, 1};
              }).ok());
}

TEST(AdvantageConfigTest, OrderRankWithinEnsemble) {
  AdvantageConfig config;
  config.ensemble = {1, 2, 3};
  config.statistic = *ParseStatistic("order:3");
  EXPECT_TRUE(config.Validate().ok());
  config.statistic = *ParseStatistic("order:4");
  EXPECT_THAT(config.Validate().message(),
              HasSubstr("order:4 needs a rank in 1..3"));
}

}  // namespace
}  // namespace vantage
