#include "actor/remote/actor_metrics.h"

#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/fakes/http_get.h"

namespace vantage {
namespace {

using ::testing::Contains;
using ::testing::HasSubstr;

std::unique_ptr<ActorMetrics> StartOnAnyPort() {
  absl::StatusOr<std::unique_ptr<ActorMetrics>> metrics =
      ActorMetrics::Start("127.0.0.1:0");
  EXPECT_TRUE(metrics.ok()) << metrics.status();
  if (!metrics.ok()) return nullptr;
  EXPECT_GT((*metrics)->port(), 0);
  return *std::move(metrics);
}

std::vector<std::string> Scrape(const ActorMetrics& metrics) {
  absl::StatusOr<std::string> body = HttpGet(metrics.port(), "/metrics");
  EXPECT_TRUE(body.ok()) << body.status();
  if (!body.ok()) return {};
  return absl::StrSplit(*body, '\n');
}

TEST(ActorMetricsTest, ServesRecordedValuesWithHelp) {
  std::unique_ptr<ActorMetrics> metrics = StartOnAnyPort();
  ASSERT_NE(metrics, nullptr);
  metrics->RecordEnvSteps(4096);
  metrics->AddSegmentsSent(2);
  metrics->AddSegmentsSent(1);
  metrics->AddInferenceSeconds(0.25);
  metrics->AddInferenceSeconds(0.5);
  metrics->AddEnvSeconds(1.5);
  metrics->AddSendSeconds(0.125);
  metrics->SetPolicyVersion(7);
  metrics->AddReconnect();

  const std::vector<std::string> lines = Scrape(*metrics);
  for (const char* line : {
           "vantage_actor_env_steps_total 4096",
           "vantage_actor_segments_sent_total 3",
           "vantage_actor_inference_seconds_total 0.75",
           "vantage_actor_env_seconds_total 1.5",
           "vantage_actor_send_seconds_total 0.125",
           "vantage_actor_policy_version 7",
           "vantage_actor_reconnects_total 1",
           "# TYPE vantage_actor_env_steps_total counter",
           "# TYPE vantage_actor_inference_seconds_total counter",
           "# TYPE vantage_actor_policy_version gauge",
       }) {
    EXPECT_THAT(lines, Contains(line));
  }
  for (const char* name :
       {"env_steps_total", "segments_sent_total", "inference_seconds_total",
        "env_seconds_total", "send_seconds_total", "policy_version",
        "reconnects_total"}) {
    EXPECT_THAT(
        lines,
        Contains(HasSubstr(absl::StrCat("# HELP vantage_actor_", name, " "))))
        << name;
  }
}

TEST(ActorMetricsTest, SameEnvStepTotalTwiceCountsOnce) {
  std::unique_ptr<ActorMetrics> metrics = StartOnAnyPort();
  ASSERT_NE(metrics, nullptr);
  metrics->RecordEnvSteps(4096);
  metrics->RecordEnvSteps(4096);
  EXPECT_THAT(Scrape(*metrics), Contains("vantage_actor_env_steps_total 4096"));
  metrics->RecordEnvSteps(6144);
  metrics->RecordEnvSteps(5000);
  EXPECT_THAT(Scrape(*metrics), Contains("vantage_actor_env_steps_total 6144"));
}

TEST(ActorMetricsTest, BadDurationsAreIgnored) {
  std::unique_ptr<ActorMetrics> metrics = StartOnAnyPort();
  ASSERT_NE(metrics, nullptr);
  metrics->AddEnvSeconds(2.0);
  metrics->AddEnvSeconds(std::numeric_limits<double>::quiet_NaN());
  metrics->AddEnvSeconds(std::numeric_limits<double>::infinity());
  metrics->AddEnvSeconds(-1.0);
  metrics->AddSegmentsSent(-4);
  const std::vector<std::string> lines = Scrape(*metrics);
  EXPECT_THAT(lines, Contains("vantage_actor_env_seconds_total 2"));
  EXPECT_THAT(lines, Contains("vantage_actor_segments_sent_total 0"));
}

TEST(ActorMetricsTest, AddressInUseIsAnErrorNamingIt) {
  std::unique_ptr<ActorMetrics> first = StartOnAnyPort();
  ASSERT_NE(first, nullptr);
  const std::string address = absl::StrCat("127.0.0.1:", first->port());
  absl::StatusOr<std::unique_ptr<ActorMetrics>> second =
      ActorMetrics::Start(address);
  ASSERT_FALSE(second.ok());
  EXPECT_EQ(second.status().code(), absl::StatusCode::kUnavailable);
  EXPECT_THAT(second.status().message(), HasSubstr(address));
  EXPECT_THAT(Scrape(*first), Contains("vantage_actor_reconnects_total 0"));
}

}  // namespace
}  // namespace vantage
