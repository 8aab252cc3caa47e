#ifndef VANTAGE_ACTOR_REMOTE_ACTOR_METRICS_H_
#define VANTAGE_ACTOR_REMOTE_ACTOR_METRICS_H_

// An actor's Prometheus endpoint (GET /metrics). Every method takes plain
// values, so the actor core stays unaware of Prometheus. Time is exported
// as counters of accumulated seconds: rate() of each gives the share of
// wall time spent there, which is what tells a slow actor's bottleneck.

#include <cstdint>
#include <memory>
#include <mutex>
#include <string>

#include "absl/status/statusor.h"
#include "common/metrics/metrics_registry.h"

namespace vantage {

class ActorMetrics {
 public:
  // Serves the metrics over HTTP on `bind_address` ("IP:PORT", e.g.
  // "0.0.0.0:9101", or "PORT" for 127.0.0.1; port 0 lets the OS choose,
  // see port()). Bound beyond loopback with an `auth_token`, it answers
  // only HTTP basic auth "vantage:<token>". An address that cannot be
  // bound (in use, malformed, not local) is an Unavailable error naming it.
  static absl::StatusOr<std::unique_ptr<ActorMetrics>> Start(
      const std::string& bind_address, const std::string& auth_token = "");
  ~ActorMetrics();

  ActorMetrics(const ActorMetrics&) = delete;
  ActorMetrics& operator=(const ActorMetrics&) = delete;

  // The port actually listened on.
  int port() const;

  // The actor's running total of environment steps (ActorCore::env_steps(),
  // kept across reconnects); the counter advances by the difference to the
  // highest total seen, so reporting the same total twice counts once.
  void RecordEnvSteps(int64_t env_steps_total);
  void AddSegmentsSent(int64_t segments);
  // Time spent in batched policy inference, in environment steps, and in
  // sending segments. Negative or non-finite durations are ignored.
  void AddInferenceSeconds(double seconds);
  void AddEnvSeconds(double seconds);
  void AddSendSeconds(double seconds);
  // The version of the weights the actor acts with.
  void SetPolicyVersion(int64_t version);
  void AddReconnect();

 private:
  ActorMetrics();

  MetricsRegistry metrics_;  // first: every series below lives in it
  prometheus::Counter& env_steps_;
  prometheus::Counter& segments_sent_;
  prometheus::Counter& inference_seconds_;
  prometheus::Counter& env_seconds_;
  prometheus::Counter& send_seconds_;
  prometheus::Gauge& policy_version_;
  prometheus::Counter& reconnects_;

  std::mutex mutex_;  // guards env_steps_total_
  TotalCounter env_steps_total_;
};

}  // namespace vantage

#endif  // VANTAGE_ACTOR_REMOTE_ACTOR_METRICS_H_
