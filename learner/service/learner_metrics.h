#ifndef VANTAGE_LEARNER_SERVICE_LEARNER_METRICS_H_
#define VANTAGE_LEARNER_SERVICE_LEARNER_METRICS_H_

// The learner's Prometheus endpoint (GET /metrics). Every method takes
// plain values, so the learner core and the gateway stay unaware of
// Prometheus; the process that owns them reports into this.

#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "common/metrics/metrics_registry.h"

namespace vantage {

class LearnerMetrics {
 public:
  // Serves the metrics over HTTP on `bind_address` ("IP:PORT", e.g.
  // "0.0.0.0:9100", or "PORT" for 127.0.0.1; port 0 lets the OS choose,
  // see port()). Bound beyond loopback with an `auth_token`, it answers
  // only HTTP basic auth "vantage:<token>". An address that cannot be
  // bound (in use, malformed, not local) is an Unavailable error naming it.
  static absl::StatusOr<std::unique_ptr<LearnerMetrics>> Start(
      const std::string& bind_address, const std::string& auth_token = "");
  ~LearnerMetrics();

  LearnerMetrics(const LearnerMetrics&) = delete;
  LearnerMetrics& operator=(const LearnerMetrics&) = delete;

  // The port actually listened on.
  int port() const;

  // After an update that published `policy_version`: the update is
  // counted, `update_seconds` observed and the time of the last update set
  // (it starts at the process's start), only if `policy_version` is above
  // the last one recorded, so the same update recorded twice counts once.
  // The update's values (version, steps, episodes, return, ...) are its
  // statistics (RecordStatistics), which alone set their series.
  void RecordUpdate(int64_t policy_version, double update_seconds);
  // Running total of segments admitted into the learner's queue.
  void RecordSegmentsAccepted(int64_t total_segments);
  // Running totals of refused segments and calls by reason (the gateway's
  // "malformed", "invalid", "foreign_actor", "foreign_slot", "stale", ...;
  // docs/security.md lists them).
  // Each reason's total must come from a single counting source.
  void RecordRejected(const std::map<std::string, int64_t>& totals_by_reason);
  // Versions between the newest policy and the one that acted an admitted
  // segment. Negative lags (future versions are refused) are ignored.
  void RecordPolicyLag(int64_t lag);
  // Segments waiting in the learner's queue, and steps held in the
  // stitcher's buffers and pending rollouts.
  void SetQueueDepth(int64_t segments, int64_t buffered_steps);
  // Who is connected: live registrations, their open segment streams and
  // weight subscriptions, the running totals of registrations granted,
  // expired and expired as stalled, the env slots of the actors with a
  // call open (the pool) and the grant of horizons each has.
  struct Actors {
    int64_t live_actors = 0;
    int64_t live_streams = 0;
    int64_t registrations_total = 0;
    int64_t expirations_total = 0;
    int64_t stalls_total = 0;
    int64_t live_env_slots = 0;
    int64_t granted_horizons = 0;
  };
  void RecordActors(const Actors& actors);

  // The update's statistics, each a gauge prefix + name (or, if `total`,
  // a counter fed from that running total: it advances by the difference
  // to the highest total seen), created on first report (the learner's
  // own series, such as env_steps_total and mean_return, exist from the
  // start); the same name must always come with
  // the same help and kind. A non-finite value (a statistic the algorithm
  // has not got) leaves its series as it was.
  struct Statistic {
    std::string name;
    std::string help;
    double value = 0.0;
    bool total = false;
  };
  void RecordStatistics(const std::vector<Statistic>& statistics);
  // Where an update's wall time went: the critic's values and the
  // advantages, the algorithm's optimisation, publishing the weights.
  void AddUpdatePhases(double advantage_seconds, double optimisation_seconds,
                       double publish_seconds);
  // The live registrations, replacing the last report: per actor id, the
  // steps of its admitted segments (a running total) and when it was last
  // heard from (Unix seconds). An actor no longer reported loses its
  // series, so ids of actors long gone do not pile up.
  struct ActorActivity {
    int64_t actor_id = 0;
    int64_t accepted_steps = 0;
    double last_seen_unix_seconds = 0.0;
  };
  void RecordActorActivity(const std::vector<ActorActivity>& actors);
  // The run's limit on policy lag (negative: none), for alerts to compare
  // the lag histogram with.
  void SetMaxPolicyLag(int64_t max_policy_lag);

 private:
  LearnerMetrics();
  // The series of one refusal reason, created on first use.
  TotalCounter& RejectedTotal(const std::string& reason);
  struct ActorSeries {
    prometheus::Counter* steps = nullptr;
    prometheus::Gauge* last_seen = nullptr;
    std::unique_ptr<TotalCounter> steps_total;
  };

  MetricsRegistry metrics_;  // first: every series below lives in it
  prometheus::Counter& env_steps_;
  prometheus::Counter& segments_accepted_;
  prometheus::Family<prometheus::Counter>& segments_rejected_;
  prometheus::Gauge& policy_version_;
  prometheus::Histogram& policy_lag_;
  prometheus::Gauge& queue_depth_;
  prometheus::Gauge& buffered_steps_;
  prometheus::Histogram& update_seconds_;
  prometheus::Gauge& mean_return_;
  prometheus::Gauge& steps_per_second_;
  prometheus::Counter& updates_;
  prometheus::Counter& episodes_;
  prometheus::Gauge& live_actors_;
  prometheus::Gauge& live_streams_;
  prometheus::Gauge& live_env_slots_;
  prometheus::Gauge& granted_horizons_;
  prometheus::Counter& stalls_;
  prometheus::Counter& registrations_;
  prometheus::Counter& expirations_;
  prometheus::Counter& rolled_back_updates_;
  prometheus::Family<prometheus::Counter>& phase_seconds_;
  prometheus::Counter& advantage_seconds_;
  prometheus::Counter& optimisation_seconds_;
  prometheus::Counter& publish_seconds_;
  prometheus::Gauge& max_policy_lag_;
  prometheus::Gauge& last_update_time_;
  prometheus::Family<prometheus::Counter>& actor_steps_;
  prometheus::Family<prometheus::Gauge>& actor_last_seen_;

  // Guards the totals: the learner loop and the gRPC threads both report.
  std::mutex mutex_;
  int64_t last_update_version_ = 0;
  TotalCounter env_steps_total_;
  TotalCounter episodes_total_;
  TotalCounter segments_accepted_total_;
  TotalCounter registrations_total_;
  TotalCounter expirations_total_;
  TotalCounter stalls_total_;
  TotalCounter rolled_back_total_;
  std::map<std::string, TotalCounter> rejected_totals_;
  // The statistics' gauges by name (the ones above among them).
  std::map<std::string, prometheus::Gauge*> statistics_;
  std::map<std::string, TotalCounter*> statistic_totals_;
  std::map<std::string, std::unique_ptr<TotalCounter>> own_totals_;
  std::map<int64_t, ActorSeries> actor_series_;
};

}  // namespace vantage

#endif  // VANTAGE_LEARNER_SERVICE_LEARNER_METRICS_H_
