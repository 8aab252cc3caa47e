#include "learner/service/learner_metrics.h"

#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"
#include "absl/time/clock.h"
#include "absl/time/time.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/fakes/http_get.h"

namespace vantage {
namespace {

using ::testing::Contains;
using ::testing::HasSubstr;
using ::testing::Not;

std::unique_ptr<LearnerMetrics> StartOnAnyPort() {
  absl::StatusOr<std::unique_ptr<LearnerMetrics>> metrics =
      LearnerMetrics::Start("127.0.0.1:0");
  EXPECT_TRUE(metrics.ok()) << metrics.status();
  if (!metrics.ok()) return nullptr;
  EXPECT_GT((*metrics)->port(), 0);
  return *std::move(metrics);
}

// The exposition text's lines, as a scraper sees them.
std::vector<std::string> Scrape(const LearnerMetrics& metrics) {
  absl::StatusOr<std::string> body = HttpGet(metrics.port(), "/metrics");
  EXPECT_TRUE(body.ok()) << body.status();
  if (!body.ok()) return {};
  return absl::StrSplit(*body, '\n');
}

// An update as the learner reports one: its progress row's statistics
// (the only source of their series), then the update itself.
void RecordUpdateRow(LearnerMetrics& metrics, int64_t policy_version,
                     int64_t env_steps_total, int64_t episodes_total,
                     double update_seconds, double mean_return,
                     double steps_per_second) {
  metrics.RecordStatistics(
      {{"policy_version", "Policy version.",
        static_cast<double>(policy_version)},
       {"env_steps_total", "Steps.", static_cast<double>(env_steps_total),
        /*total=*/true},
       {"episodes_total", "Episodes.", static_cast<double>(episodes_total),
        /*total=*/true},
       {"mean_return", "Return.", mean_return},
       {"steps_per_second", "Rate.", steps_per_second}});
  metrics.RecordUpdate(policy_version, update_seconds);
}

TEST(LearnerMetricsTest, ServesRecordedValuesWithHelp) {
  std::unique_ptr<LearnerMetrics> metrics = StartOnAnyPort();
  ASSERT_NE(metrics, nullptr);
  RecordUpdateRow(*metrics, /*policy_version=*/1, /*env_steps_total=*/4096,
                  /*episodes_total=*/3, /*update_seconds=*/0.5,
                  /*mean_return=*/12.5, /*steps_per_second=*/1000);
  metrics->RecordSegmentsAccepted(32);
  metrics->RecordRejected({{"stale", 3}, {"malformed", 1}});
  metrics->SetQueueDepth(5, 640);
  metrics->RecordActors({/*live_actors=*/2, /*live_streams=*/4,
                         /*registrations_total=*/5, /*expirations_total=*/3});
  metrics->RecordStatistics(
      {{"rolled_back_updates_total", "Rolled back.", 1, /*total=*/true}});

  const std::vector<std::string> lines = Scrape(*metrics);
  for (const char* line : {
           "vantage_learner_env_steps_total 4096",
           "vantage_learner_episodes_total 3",
           "vantage_learner_updates_total 1",
           "vantage_learner_policy_version 1",
           "vantage_learner_mean_return 12.5",
           "vantage_learner_steps_per_second 1000",
           "vantage_learner_segments_accepted_total 32",
           "vantage_learner_segments_rejected_total{reason=\"stale\"} 3",
           "vantage_learner_segments_rejected_total{reason=\"malformed\"} 1",
           "vantage_learner_queue_depth 5",
           "vantage_learner_buffered_steps 640",
           "vantage_learner_live_actors 2",
           "vantage_learner_live_streams 4",
           "vantage_learner_registrations_total 5",
           "vantage_learner_registration_expirations_total 3",
           "vantage_learner_rolled_back_updates_total 1",
           "vantage_learner_update_seconds_count 1",
           "vantage_learner_update_seconds_sum 0.5",
           "vantage_learner_update_seconds_bucket{le=\"0.25\"} 0",
           "vantage_learner_update_seconds_bucket{le=\"0.5\"} 1",
           "vantage_learner_update_seconds_bucket{le=\"60\"} 1",
           "# TYPE vantage_learner_env_steps_total counter",
           "# TYPE vantage_learner_policy_lag histogram",
           "# TYPE vantage_learner_mean_return gauge",
       }) {
    EXPECT_THAT(lines, Contains(line));
  }
  for (const char* name :
       {"env_steps_total", "segments_accepted_total", "segments_rejected_total",
        "policy_version", "policy_lag", "queue_depth", "buffered_steps",
        "update_seconds", "mean_return", "steps_per_second", "updates_total",
        "episodes_total", "live_actors", "live_streams", "registrations_total",
        "registration_expirations_total", "rolled_back_updates_total"}) {
    EXPECT_THAT(
        lines,
        Contains(HasSubstr(absl::StrCat("# HELP vantage_learner_", name, " "))))
        << name;
  }
}

TEST(LearnerMetricsTest, KnownRejectReasonsStartAtZero) {
  std::unique_ptr<LearnerMetrics> metrics = StartOnAnyPort();
  ASSERT_NE(metrics, nullptr);
  const std::vector<std::string> lines = Scrape(*metrics);
  for (const char* reason :
       {"malformed", "invalid", "foreign_actor", "foreign_slot",
        "unknown_session", "future_version", "stale", "duplicate"}) {
    EXPECT_THAT(lines, Contains(absl::StrCat(
                           "vantage_learner_segments_rejected_total{reason=\"",
                           reason, "\"} 0")));
  }
}

TEST(LearnerMetricsTest, SameTotalsTwiceCountOnce) {
  std::unique_ptr<LearnerMetrics> metrics = StartOnAnyPort();
  ASSERT_NE(metrics, nullptr);
  for (int i = 0; i < 2; ++i) {
    RecordUpdateRow(*metrics, 1, 4096, 3, 0.5, 12.5, 1000);
    metrics->RecordSegmentsAccepted(32);
    metrics->RecordRejected({{"stale", 3}});
  }
  std::vector<std::string> lines = Scrape(*metrics);
  EXPECT_THAT(lines, Contains("vantage_learner_env_steps_total 4096"));
  EXPECT_THAT(lines, Contains("vantage_learner_episodes_total 3"));
  EXPECT_THAT(lines, Contains("vantage_learner_updates_total 1"));
  EXPECT_THAT(lines, Contains("vantage_learner_update_seconds_count 1"));
  EXPECT_THAT(lines, Contains("vantage_learner_segments_accepted_total 32"));
  EXPECT_THAT(
      lines,
      Contains("vantage_learner_segments_rejected_total{reason=\"stale\"} 3"));

  // Newer totals add their difference; an older total arriving late adds
  // nothing.
  RecordUpdateRow(*metrics, 2, 8192, 5, 0.25, 13.0, 1100);
  RecordUpdateRow(*metrics, 1, 4096, 3, 0.5, 12.5, 1000);
  metrics->RecordSegmentsAccepted(40);
  metrics->RecordSegmentsAccepted(35);
  metrics->RecordRejected({{"stale", 7}, {"unknown_actor", 2}});
  metrics->RecordRejected({{"stale", 5}});
  lines = Scrape(*metrics);
  EXPECT_THAT(lines, Contains("vantage_learner_env_steps_total 8192"));
  EXPECT_THAT(lines, Contains("vantage_learner_episodes_total 5"));
  EXPECT_THAT(lines, Contains("vantage_learner_updates_total 2"));
  EXPECT_THAT(lines, Contains("vantage_learner_update_seconds_count 2"));
  EXPECT_THAT(lines, Contains("vantage_learner_segments_accepted_total 40"));
  EXPECT_THAT(
      lines,
      Contains("vantage_learner_segments_rejected_total{reason=\"stale\"} 7"));
  EXPECT_THAT(lines, Contains("vantage_learner_segments_rejected_total{reason="
                              "\"unknown_actor\"} 2"));
}

TEST(LearnerMetricsTest, TotalsFromManyThreadsCountOnce) {
  std::unique_ptr<LearnerMetrics> metrics = StartOnAnyPort();
  ASSERT_NE(metrics, nullptr);
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t) {
    threads.emplace_back([&metrics] {
      for (int64_t total = 1; total <= 1000; ++total) {
        metrics->RecordSegmentsAccepted(total);
        metrics->RecordRejected({{"invalid", total}});
      }
    });
  }
  for (std::thread& thread : threads) thread.join();
  const std::vector<std::string> lines = Scrape(*metrics);
  EXPECT_THAT(lines, Contains("vantage_learner_segments_accepted_total 1000"));
  EXPECT_THAT(
      lines,
      Contains(
          "vantage_learner_segments_rejected_total{reason=\"invalid\"} 1000"));
}

TEST(LearnerMetricsTest, NanMeanReturnKeepsTheGauge) {
  std::unique_ptr<LearnerMetrics> metrics = StartOnAnyPort();
  ASSERT_NE(metrics, nullptr);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  RecordUpdateRow(*metrics, 1, 100, 0, 0.1, nan, 50);
  EXPECT_THAT(Scrape(*metrics), Contains("vantage_learner_mean_return 0"));
  RecordUpdateRow(*metrics, 2, 200, 1, 0.1, -3.5, 50);
  RecordUpdateRow(*metrics, 3, 300, 1, 0.1, nan, nan);
  const std::vector<std::string> lines = Scrape(*metrics);
  EXPECT_THAT(lines, Contains("vantage_learner_mean_return -3.5"));
  EXPECT_THAT(lines, Contains("vantage_learner_steps_per_second 50"));
  EXPECT_THAT(lines, Contains("vantage_learner_policy_version 3"));
  EXPECT_THAT(lines, Not(Contains(HasSubstr("NaN"))));
  EXPECT_THAT(lines, Not(Contains(HasSubstr("Nan"))));
}

TEST(LearnerMetricsTest, PolicyLagHistogramBuckets) {
  std::unique_ptr<LearnerMetrics> metrics = StartOnAnyPort();
  ASSERT_NE(metrics, nullptr);
  for (int64_t lag : {0, 1, 1, 3, 16, 40, -1}) metrics->RecordPolicyLag(lag);
  const std::vector<std::string> lines = Scrape(*metrics);
  for (const char* line : {
           "vantage_learner_policy_lag_bucket{le=\"0\"} 1",
           "vantage_learner_policy_lag_bucket{le=\"1\"} 3",
           "vantage_learner_policy_lag_bucket{le=\"2\"} 3",
           "vantage_learner_policy_lag_bucket{le=\"4\"} 4",
           "vantage_learner_policy_lag_bucket{le=\"8\"} 4",
           "vantage_learner_policy_lag_bucket{le=\"16\"} 5",
           "vantage_learner_policy_lag_bucket{le=\"32\"} 5",
           "vantage_learner_policy_lag_bucket{le=\"+Inf\"} 6",
           "vantage_learner_policy_lag_count 6",
           "vantage_learner_policy_lag_sum 61",
       }) {
    EXPECT_THAT(lines, Contains(line));
  }
}

TEST(LearnerMetricsTest, AddressInUseIsAnErrorNamingIt) {
  std::unique_ptr<LearnerMetrics> first = StartOnAnyPort();
  ASSERT_NE(first, nullptr);
  const std::string address = absl::StrCat("127.0.0.1:", first->port());
  absl::StatusOr<std::unique_ptr<LearnerMetrics>> second =
      LearnerMetrics::Start(address);
  ASSERT_FALSE(second.ok());
  EXPECT_EQ(second.status().code(), absl::StatusCode::kUnavailable);
  EXPECT_THAT(second.status().message(), HasSubstr(address));
  // The first one still serves.
  EXPECT_THAT(Scrape(*first), Contains("vantage_learner_updates_total 0"));
}

TEST(LearnerMetricsTest, MalformedAddressIsAnError) {
  for (const char* address : {"", "not an address", "127.0.0.1:99999"}) {
    absl::StatusOr<std::unique_ptr<LearnerMetrics>> metrics =
        LearnerMetrics::Start(address);
    EXPECT_FALSE(metrics.ok()) << address;
  }
}

TEST(LearnerMetricsTest, StatisticsAreGaugesOrCountersByKind) {
  std::unique_ptr<LearnerMetrics> metrics = StartOnAnyPort();
  ASSERT_NE(metrics, nullptr);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  metrics->RecordStatistics({{"value_loss", "Critic loss.", 2.5},
                             {"clip_fraction", "Clipped share.", 0.25},
                             {"batch_rejected_segments_total", "Refused.", 4,
                              /*total=*/true},
                             // The learner's own series: the same one.
                             {"env_steps_total", "Steps.", 4096, true},
                             {"mean_return", "Return.", 7.0}});
  RecordUpdateRow(*metrics, 1, 4096, 3, 0.5, 7.0, 1000);
  // A statistic the algorithm has not got keeps its gauge; totals only
  // grow by their difference.
  metrics->RecordStatistics(
      {{"value_loss", "Critic loss.", nan},
       {"batch_rejected_segments_total", "Refused.", 6, true},
       {"env_steps_total", "Steps.", 4096, true}});
  const std::vector<std::string> lines = Scrape(*metrics);
  for (const char* line : {
           "vantage_learner_value_loss 2.5",
           "vantage_learner_clip_fraction 0.25",
           "vantage_learner_batch_rejected_segments_total 6",
           "vantage_learner_env_steps_total 4096",
           "vantage_learner_mean_return 7",
           "# TYPE vantage_learner_value_loss gauge",
           "# TYPE vantage_learner_batch_rejected_segments_total counter",
           "# HELP vantage_learner_value_loss Critic loss.",
       }) {
    EXPECT_THAT(lines, Contains(line));
  }
}

TEST(LearnerMetricsTest, UpdatePhasesAndTheLastUpdateTime) {
  std::unique_ptr<LearnerMetrics> metrics = StartOnAnyPort();
  ASSERT_NE(metrics, nullptr);
  metrics->AddUpdatePhases(0.25, 1.5, 0.125);
  metrics->AddUpdatePhases(0.25, -1, std::nan(""));
  metrics->SetMaxPolicyLag(3);
  const double before = absl::ToDoubleSeconds(absl::Now() - absl::UnixEpoch());
  RecordUpdateRow(*metrics, 1, 10, 0, 0.1, 0, 10);
  const std::vector<std::string> lines = Scrape(*metrics);
  for (const char* line : {
           "vantage_learner_update_phase_seconds_total{phase=\"advantages\"} "
           "0.5",
           "vantage_learner_update_phase_seconds_total{phase=\"optimisation\"}"
           " 1.5",
           "vantage_learner_update_phase_seconds_total{phase=\"publish\"} "
           "0.125",
           "vantage_learner_max_policy_lag 3",
       }) {
    EXPECT_THAT(lines, Contains(line));
  }
  double last_update = 0;
  for (absl::string_view line : lines) {
    if (absl::ConsumePrefix(&line,
                            "vantage_learner_last_update_timestamp_seconds ")) {
      ASSERT_TRUE(absl::SimpleAtod(line, &last_update)) << line;
    }
  }
  EXPECT_GE(last_update, std::floor(before));
  EXPECT_LE(last_update, before + 60);
}

TEST(LearnerMetricsTest, ActorSeriesFollowTheLiveRegistrations) {
  std::unique_ptr<LearnerMetrics> metrics = StartOnAnyPort();
  ASSERT_NE(metrics, nullptr);
  metrics->RecordActorActivity({{3, 100, 1000.5}, {4, 50, 1001}});
  metrics->RecordActorActivity({{3, 300, 1002}, {4, 50, 1001}});
  std::vector<std::string> lines = Scrape(*metrics);
  EXPECT_THAT(lines, Contains("vantage_learner_actor_env_steps_total{actor_id="
                              "\"3\"} 300"));
  EXPECT_THAT(lines, Contains("vantage_learner_actor_env_steps_total{actor_id="
                              "\"4\"} 50"));
  EXPECT_THAT(lines, Contains("vantage_learner_actor_last_seen_timestamp_"
                              "seconds{actor_id=\"3\"} 1002"));
  // Actor 4 expired: its series go, so restarted actors' ids do not pile up.
  metrics->RecordActorActivity({{3, 320, 1003}});
  lines = Scrape(*metrics);
  EXPECT_THAT(lines, Contains("vantage_learner_actor_env_steps_total{actor_id="
                              "\"3\"} 320"));
  EXPECT_THAT(lines, Not(Contains(HasSubstr("actor_id=\"4\""))));
}

}  // namespace
}  // namespace vantage
