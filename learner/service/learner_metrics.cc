#include "learner/service/learner_metrics.h"

#include <cmath>
#include <exception>
#include <utility>
#include <vector>

#include "absl/memory/memory.h"
#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "common/metrics/metrics_endpoint.h"

namespace vantage {
namespace {

// The reasons the gateway refuses segments for; created up front so that
// their series exist (at 0) before the first refusal and rate() works.
constexpr const char* kKnownRejectReasons[] = {
    "malformed",      "invalid",      "unparsable",  "oversized",
    "foreign_actor",  "foreign_slot", "bad_session", "unknown_session",
    "future_version", "stale",        "duplicate",   "idle_stream"};

prometheus::Counter& AddCounter(prometheus::Registry& registry,
                                const std::string& name,
                                const std::string& help) {
  return prometheus::BuildCounter()
      .Name("vantage_learner_" + name)
      .Help(help)
      .Register(registry)
      .Add({});
}

prometheus::Gauge& AddGauge(prometheus::Registry& registry,
                            const std::string& name, const std::string& help) {
  return prometheus::BuildGauge()
      .Name("vantage_learner_" + name)
      .Help(help)
      .Register(registry)
      .Add({});
}

prometheus::Histogram& AddHistogram(
    prometheus::Registry& registry, const std::string& name,
    const std::string& help,
    const prometheus::Histogram::BucketBoundaries& buckets) {
  return prometheus::BuildHistogram()
      .Name("vantage_learner_" + name)
      .Help(help)
      .Register(registry)
      .Add({}, buckets);
}

}  // namespace

LearnerMetrics::LearnerMetrics()
    : registry_(std::make_shared<prometheus::Registry>()),
      env_steps_(AddCounter(*registry_, "env_steps_total",
                            "Environment steps consumed by updates.")),
      segments_accepted_(
          AddCounter(*registry_, "segments_accepted_total",
                     "Segments admitted into the learner's queue.")),
      segments_rejected_(prometheus::BuildCounter()
                             .Name("vantage_learner_segments_rejected_total")
                             .Help("Segments refused or dropped, by reason.")
                             .Register(*registry_)),
      policy_version_(AddGauge(*registry_, "policy_version",
                               "Newest published policy version.")),
      policy_lag_(AddHistogram(
          *registry_, "policy_lag",
          "Versions between the newest policy and the one that acted an "
          "admitted segment.",
          {0, 1, 2, 4, 8, 16, 32})),
      queue_depth_(AddGauge(*registry_, "queue_depth",
                            "Segments waiting in the learner's queue.")),
      buffered_steps_(
          AddGauge(*registry_, "buffered_steps",
                   "Steps held in stitching buffers and pending rollouts.")),
      update_seconds_(AddHistogram(
          *registry_, "update_seconds",
          "Wall time of one update (advantages and optimisation).",
          {0.01, 0.025, 0.05, 0.1, 0.25, 0.5, 1, 2.5, 5, 10, 30, 60})),
      mean_return_(AddGauge(*registry_, "mean_return",
                            "Mean return of the last 100 finished episodes.")),
      steps_per_second_(AddGauge(*registry_, "steps_per_second",
                                 "Environment steps consumed per second.")),
      updates_(AddCounter(*registry_, "updates_total",
                          "Updates made by this learner process.")),
      episodes_(AddCounter(*registry_, "episodes_total",
                           "Episodes finished in consumed segments.")),
      live_actors_(AddGauge(*registry_, "live_actors",
                            "Actor registrations that have not expired.")),
      live_streams_(AddGauge(*registry_, "live_streams",
                             "Open segment streams and weight subscriptions "
                             "of registered actors.")),
      registrations_(AddCounter(*registry_, "registrations_total",
                                "Actor registrations granted.")),
      expirations_(AddCounter(*registry_, "registration_expirations_total",
                              "Registrations expired after their actor left.")),
      rolled_back_updates_(AddCounter(
          *registry_, "rolled_back_updates_total",
          "Updates undone because they produced non-finite numbers.")) {
  for (const char* reason : kKnownRejectReasons) RejectedCounter(reason);
}

LearnerMetrics::~LearnerMetrics() = default;

absl::StatusOr<std::unique_ptr<LearnerMetrics>> LearnerMetrics::Start(
    const std::string& bind_address, const std::string& auth_token) {
  auto metrics = absl::WrapUnique(new LearnerMetrics());
  absl::StatusOr<std::unique_ptr<prometheus::Exposer>> exposer =
      StartMetricsEndpoint({bind_address, auth_token}, metrics->registry_,
                           "learner");
  if (!exposer.ok()) return exposer.status();
  metrics->exposer_ = *std::move(exposer);
  return metrics;
}

int LearnerMetrics::port() const { return MetricsPort(*exposer_); }

void LearnerMetrics::RecordUpdate(int64_t policy_version,
                                  int64_t env_steps_total,
                                  int64_t episodes_total, double update_seconds,
                                  double mean_return, double steps_per_second) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (policy_version > last_update_version_) {
    last_update_version_ = policy_version;
    updates_.Increment();
    // A NaN would poison the histogram's sum for good.
    if (std::isfinite(update_seconds) && update_seconds >= 0) {
      update_seconds_.Observe(update_seconds);
    }
  }
  policy_version_.Set(static_cast<double>(policy_version));
  env_steps_.Increment(
      static_cast<double>(env_steps_total_.Advance(env_steps_total)));
  episodes_.Increment(
      static_cast<double>(episodes_total_.Advance(episodes_total)));
  if (std::isfinite(mean_return)) mean_return_.Set(mean_return);
  if (std::isfinite(steps_per_second)) steps_per_second_.Set(steps_per_second);
}

void LearnerMetrics::RecordSegmentsAccepted(int64_t total_segments) {
  std::lock_guard<std::mutex> lock(mutex_);
  segments_accepted_.Increment(
      static_cast<double>(segments_accepted_total_.Advance(total_segments)));
}

void LearnerMetrics::RecordRejected(
    const std::map<std::string, int64_t>& totals_by_reason) {
  std::lock_guard<std::mutex> lock(mutex_);
  for (const auto& [reason, total] : totals_by_reason) {
    const int64_t increment = rejected_totals_[reason].Advance(total);
    if (increment > 0) {
      RejectedCounter(reason).Increment(static_cast<double>(increment));
    }
  }
}

void LearnerMetrics::RecordPolicyLag(int64_t lag) {
  if (lag < 0) return;
  policy_lag_.Observe(static_cast<double>(lag));
}

void LearnerMetrics::SetQueueDepth(int64_t segments, int64_t buffered_steps) {
  queue_depth_.Set(static_cast<double>(segments));
  buffered_steps_.Set(static_cast<double>(buffered_steps));
}

void LearnerMetrics::RecordActors(const Actors& actors) {
  std::lock_guard<std::mutex> lock(mutex_);
  live_actors_.Set(static_cast<double>(actors.live_actors));
  live_streams_.Set(static_cast<double>(actors.live_streams));
  registrations_.Increment(static_cast<double>(
      registrations_total_.Advance(actors.registrations_total)));
  expirations_.Increment(static_cast<double>(
      expirations_total_.Advance(actors.expirations_total)));
}

void LearnerMetrics::RecordRolledBackUpdates(int64_t total) {
  std::lock_guard<std::mutex> lock(mutex_);
  rolled_back_updates_.Increment(
      static_cast<double>(rolled_back_total_.Advance(total)));
}

prometheus::Counter& LearnerMetrics::RejectedCounter(
    const std::string& reason) {
  prometheus::Counter*& counter = rejected_counters_[reason];
  if (counter == nullptr)
    counter = &segments_rejected_.Add({{"reason", reason}});
  return *counter;
}

}  // namespace vantage
