#include "learner/service/learner_metrics.h"

#include <cmath>
#include <utility>

#include "absl/memory/memory.h"
#include "absl/strings/str_cat.h"

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
      live_env_slots_(metrics_.AddGauge(
          "live_env_slots",
          "Env slots of the actors with a call open: the elastic pool that "
          "fills the batch (0: no update can happen).")),
      granted_horizons_(metrics_.AddGauge(
          "granted_horizons",
          "Horizons each live env slot may act with the newest version, "
          "shared out so that the live slots fill the batch.")),
      stalls_(metrics_.AddCounter(
          "actor_stalls_total",
          "Registrations expired because their actor owed segments and "
          "sent none for --actor_stall_timeout_s.")),
      registrations_(metrics_.AddCounter("registrations_total",
                                         "Actor registrations granted.")),
      expirations_(metrics_.AddCounter(
          "registration_expirations_total",
          "Registrations expired after their actor left, never "
          "claimed, or evicted to make room.")),
      rolled_back_updates_(metrics_.AddCounter(
          "rolled_back_updates_total",
          "Updates undone because they produced non-finite numbers.")),
      phase_seconds_(metrics_.AddCounterFamily(
          "update_phase_seconds_total",
          "Wall time of updates by phase: advantages (critic values and "
          "estimates), optimisation, publish (weights to the actors).")),
      advantage_seconds_(phase_seconds_.Add({{"phase", "advantages"}})),
      optimisation_seconds_(phase_seconds_.Add({{"phase", "optimisation"}})),
      publish_seconds_(phase_seconds_.Add({{"phase", "publish"}})),
      max_policy_lag_(metrics_.AddGauge(
          "max_policy_lag",
          "The run's limit on policy lag (older segments are dropped); "
          "negative: none.")),
      last_update_time_(metrics_.AddGauge(
          "last_update_timestamp_seconds",
          "When the last update was published (Unix time; the process's "
          "start before the first).")),
      actor_steps_(metrics_.AddCounterFamily(
          "actor_env_steps_total",
          "Environment steps in the admitted segments of each live actor "
          "registration (label actor_id, the id the learner granted).")),
      actor_last_seen_(metrics_.AddGaugeFamily(
          "actor_last_seen_timestamp_seconds",
          "When each live actor registration was last heard from (Unix "
          "time).")),
      env_steps_total_(env_steps_),
      episodes_total_(episodes_),
      segments_accepted_total_(segments_accepted_),
      registrations_total_(registrations_),
      expirations_total_(expirations_),
      stalls_total_(stalls_),
      rolled_back_total_(rolled_back_updates_) {
  for (const char* reason : kKnownRejectReasons) RejectedTotal(reason);
  statistics_ = {{"policy_version", &policy_version_},
                 {"mean_return", &mean_return_},
                 {"steps_per_second", &steps_per_second_}};
  last_update_time_.SetToCurrentTime();
  statistic_totals_ = {{"env_steps_total", &env_steps_total_},
                       {"episodes_total", &episodes_total_},
                       {"rolled_back_updates_total", &rolled_back_total_}};
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
                                  double update_seconds) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (policy_version > last_update_version_) {
    last_update_version_ = policy_version;
    updates_.Increment();
    last_update_time_.SetToCurrentTime();
    // A NaN would poison the histogram's sum for good.
    if (std::isfinite(update_seconds) && update_seconds >= 0) {
      update_seconds_.Observe(update_seconds);
    }
  }
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
  live_env_slots_.Set(static_cast<double>(actors.live_env_slots));
  granted_horizons_.Set(static_cast<double>(actors.granted_horizons));
  stalls_total_.Record(actors.stalls_total);
  registrations_total_.Record(actors.registrations_total);
  expirations_total_.Record(actors.expirations_total);
}

void LearnerMetrics::RecordStatistics(
    const std::vector<Statistic>& statistics) {
  std::lock_guard<std::mutex> lock(mutex_);
  // Every series exists before any takes its value, so no scrape sees
  // some of an update's statistics without the others' series.
  for (const Statistic& statistic : statistics) {
    if (statistic.total) {
      if (statistic_totals_.count(statistic.name) > 0) continue;
      auto& owned = own_totals_[statistic.name];
      owned = std::make_unique<TotalCounter>(
          metrics_.AddCounter(statistic.name, statistic.help));
      statistic_totals_.emplace(statistic.name, owned.get());
    } else if (statistics_.count(statistic.name) == 0) {
      statistics_.emplace(statistic.name,
                          &metrics_.AddGauge(statistic.name, statistic.help));
    }
  }
  for (const Statistic& statistic : statistics) {
    if (!std::isfinite(statistic.value)) continue;
    if (statistic.total) {
      statistic_totals_.at(statistic.name)
          ->Record(static_cast<int64_t>(statistic.value));
    } else {
      statistics_.at(statistic.name)->Set(statistic.value);
    }
  }
}

void LearnerMetrics::AddUpdatePhases(double advantage_seconds,
                                     double optimisation_seconds,
                                     double publish_seconds) {
  AddSeconds(advantage_seconds_, advantage_seconds);
  AddSeconds(optimisation_seconds_, optimisation_seconds);
  AddSeconds(publish_seconds_, publish_seconds);
}

void LearnerMetrics::SetMaxPolicyLag(int64_t max_policy_lag) {
  max_policy_lag_.Set(static_cast<double>(max_policy_lag));
}

void LearnerMetrics::RecordActorActivity(
    const std::vector<ActorActivity>& actors) {
  std::lock_guard<std::mutex> lock(mutex_);
  std::map<int64_t, ActorSeries> live;
  for (const ActorActivity& actor : actors) {
    auto it = actor_series_.find(actor.actor_id);
    ActorSeries series;
    if (it != actor_series_.end()) {
      series = std::move(it->second);
      actor_series_.erase(it);
    } else {
      const std::map<std::string, std::string> labels = {
          {"actor_id", absl::StrCat(actor.actor_id)}};
      series.steps = &actor_steps_.Add(labels);
      series.last_seen = &actor_last_seen_.Add(labels);
      series.steps_total = std::make_unique<TotalCounter>(*series.steps);
    }
    series.steps_total->Record(actor.accepted_steps);
    series.last_seen->Set(actor.last_seen_unix_seconds);
    live.emplace(actor.actor_id, std::move(series));
  }
  // Whoever was not reported is gone.
  for (auto& [actor_id, series] : actor_series_) {
    actor_steps_.Remove(series.steps);
    actor_last_seen_.Remove(series.last_seen);
  }
  actor_series_ = std::move(live);
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
