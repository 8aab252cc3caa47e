#include "actor/remote/actor_metrics.h"

#include <cmath>
#include <exception>
#include <vector>

#include "absl/memory/memory.h"
#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "common/metrics/metrics_endpoint.h"

namespace vantage {
namespace {

prometheus::Counter& AddCounter(prometheus::Registry& registry,
                                const std::string& name,
                                const std::string& help) {
  return prometheus::BuildCounter()
      .Name("vantage_actor_" + name)
      .Help(help)
      .Register(registry)
      .Add({});
}

// A NaN increment would poison a counter for good; prometheus-cpp itself
// only drops negative ones.
void AddSeconds(prometheus::Counter& counter, double seconds) {
  if (std::isfinite(seconds) && seconds > 0) counter.Increment(seconds);
}

}  // namespace

ActorMetrics::ActorMetrics()
    : registry_(std::make_shared<prometheus::Registry>()),
      env_steps_(AddCounter(*registry_, "env_steps_total",
                            "Environment steps acted.")),
      segments_sent_(AddCounter(*registry_, "segments_sent_total",
                                "Segments sent to the learner.")),
      inference_seconds_(AddCounter(*registry_, "inference_seconds_total",
                                    "Seconds spent in policy inference.")),
      env_seconds_(AddCounter(*registry_, "env_seconds_total",
                              "Seconds spent stepping environments.")),
      send_seconds_(AddCounter(*registry_, "send_seconds_total",
                               "Seconds spent sending segments.")),
      policy_version_(prometheus::BuildGauge()
                          .Name("vantage_actor_policy_version")
                          .Help("Version of the weights the actor acts with.")
                          .Register(*registry_)
                          .Add({})),
      reconnects_(AddCounter(*registry_, "reconnects_total",
                             "Reconnections to the learner.")) {}

ActorMetrics::~ActorMetrics() = default;

absl::StatusOr<std::unique_ptr<ActorMetrics>> ActorMetrics::Start(
    const std::string& bind_address, const std::string& auth_token) {
  auto metrics = absl::WrapUnique(new ActorMetrics());
  absl::StatusOr<std::unique_ptr<prometheus::Exposer>> exposer =
      StartMetricsEndpoint({bind_address, auth_token}, metrics->registry_,
                           "actor");
  if (!exposer.ok()) return exposer.status();
  metrics->exposer_ = *std::move(exposer);
  return metrics;
}

int ActorMetrics::port() const { return MetricsPort(*exposer_); }

void ActorMetrics::RecordEnvSteps(int64_t env_steps_total) {
  std::lock_guard<std::mutex> lock(mutex_);
  env_steps_.Increment(
      static_cast<double>(env_steps_total_.Advance(env_steps_total)));
}

void ActorMetrics::AddSegmentsSent(int64_t segments) {
  if (segments > 0) segments_sent_.Increment(static_cast<double>(segments));
}

void ActorMetrics::AddInferenceSeconds(double seconds) {
  AddSeconds(inference_seconds_, seconds);
}

void ActorMetrics::AddEnvSeconds(double seconds) {
  AddSeconds(env_seconds_, seconds);
}

void ActorMetrics::AddSendSeconds(double seconds) {
  AddSeconds(send_seconds_, seconds);
}

void ActorMetrics::SetPolicyVersion(int64_t version) {
  policy_version_.Set(static_cast<double>(version));
}

void ActorMetrics::AddReconnect() { reconnects_.Increment(); }

}  // namespace vantage
