#include "learner/service/learner_metrics.h"

#include <cmath>
#include <utility>

#include "absl/memory/memory.h"

namespace vantage {
namespace {

// The reasons the gateway refuses segments for; created up front so that
// their series exist (at 0) before the first refusal and rate() works.
constexpr const char* kKnownRejectReasons[] = {
    "malformed",      "invalid",      "unparsable",  "oversized",
    "foreign_actor",  "foreign_slot", "bad_session", "unknown_session",
    "future_version", "stale",        "duplicate",   "idle_stream"};

}  // namespace

LearnerMetrics::LearnerMetrics()
    : metrics_("vantage_learner_"),
      env_steps_(metrics_.AddCounter("env_steps_total",
                                     "Environment steps consumed by updates.")),
      segments_accepted_(
          metrics_.AddCounter("segments_accepted_total",
                              "Segments admitted into the learner's queue.")),
      segments_rejected_(
          metrics_.AddCounterFamily("segments_rejected_total",
                                    "Segments refused or dropped, by reason.")),
      policy_version_(metrics_.AddGauge("policy_version",
                                        "Newest published policy version.")),
      policy_lag_(metrics_.AddHistogram(
          "policy_lag",
          "Versions between the newest policy and the one that acted an "
          "admitted segment.",
          {0, 1, 2, 4, 8, 16, 32})),
      queue_depth_(metrics_.AddGauge(
          "queue_depth", "Segments waiting in the learner's queue.")),
      buffered_steps_(metrics_.AddGauge(
          "buffered_steps",
          "Steps held in stitching buffers and pending rollouts.")),
      update_seconds_(metrics_.AddHistogram(
          "update_seconds",
          "Wall time of one update (advantages and optimisation).",
          {0.01, 0.025, 0.05, 0.1, 0.25, 0.5, 1, 2.5, 5, 10, 30, 60})),
      mean_return_(metrics_.AddGauge(
          "mean_return", "Mean return of the last 100 finished episodes.")),
      steps_per_second_(metrics_.AddGauge(
          "steps_per_second", "Environment steps consumed per second.")),
      updates_(metrics_.AddCounter("updates_total",
                                   "Updates made by this learner process.")),
      episodes_(metrics_.AddCounter("episodes_total",
                                    "Episodes finished in consumed segments.")),
      live_actors_(metrics_.AddGauge(
          "live_actors", "Actor registrations that have not expired.")),
      live_streams_(
          metrics_.AddGauge("live_streams",
                            "Open segment streams and weight subscriptions "
                            "of registered actors.")),
      registrations_(metrics_.AddCounter("registrations_total",
                                         "Actor registrations granted.")),
      expirations_(
          metrics_.AddCounter("registration_expirations_total",
                              "Registrations expired after their actor left.")),
      rolled_back_updates_(metrics_.AddCounter(
          "rolled_back_updates_total",
          "Updates undone because they produced non-finite numbers.")),
      env_steps_total_(env_steps_),
      episodes_total_(episodes_),
      segments_accepted_total_(segments_accepted_),
      registrations_total_(registrations_),
      expirations_total_(expirations_),
      rolled_back_total_(rolled_back_updates_) {
  for (const char* reason : kKnownRejectReasons) RejectedTotal(reason);
}

LearnerMetrics::~LearnerMetrics() = default;

absl::StatusOr<std::unique_ptr<LearnerMetrics>> LearnerMetrics::Start(
    const std::string& bind_address, const std::string& auth_token) {
  auto metrics = absl::WrapUnique(new LearnerMetrics());
  if (absl::Status status =
          metrics->metrics_.Serve({bind_address, auth_token}, "learner");
      !status.ok()) {
    return status;
  }
  return metrics;
}

int LearnerMetrics::port() const { return metrics_.port(); }

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
  env_steps_total_.Record(env_steps_total);
  episodes_total_.Record(episodes_total);
  if (std::isfinite(mean_return)) mean_return_.Set(mean_return);
  if (std::isfinite(steps_per_second)) steps_per_second_.Set(steps_per_second);
}

void LearnerMetrics::RecordSegmentsAccepted(int64_t total_segments) {
  std::lock_guard<std::mutex> lock(mutex_);
  segments_accepted_total_.Record(total_segments);
}

void LearnerMetrics::RecordRejected(
    const std::map<std::string, int64_t>& totals_by_reason) {
  std::lock_guard<std::mutex> lock(mutex_);
  for (const auto& [reason, total] : totals_by_reason) {
    RejectedTotal(reason).Record(total);
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
  registrations_total_.Record(actors.registrations_total);
  expirations_total_.Record(actors.expirations_total);
}

void LearnerMetrics::RecordRolledBackUpdates(int64_t total) {
  std::lock_guard<std::mutex> lock(mutex_);
  rolled_back_total_.Record(total);
}

TotalCounter& LearnerMetrics::RejectedTotal(const std::string& reason) {
  auto it = rejected_totals_.find(reason);
  if (it == rejected_totals_.end()) {
    it =
        rejected_totals_
            .emplace(reason,
                     TotalCounter(segments_rejected_.Add({{"reason", reason}})))
            .first;
  }
  return it->second;
}

}  // namespace vantage
