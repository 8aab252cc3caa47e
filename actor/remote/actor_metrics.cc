#include "actor/remote/actor_metrics.h"

#include "absl/memory/memory.h"

namespace vantage {

ActorMetrics::ActorMetrics()
    : metrics_("vantage_actor_"),
      env_steps_(
          metrics_.AddCounter("env_steps_total", "Environment steps acted.")),
      segments_sent_(metrics_.AddCounter("segments_sent_total",
                                         "Segments sent to the learner.")),
      inference_seconds_(metrics_.AddCounter(
          "inference_seconds_total", "Seconds spent in policy inference.")),
      env_seconds_(metrics_.AddCounter("env_seconds_total",
                                       "Seconds spent stepping environments.")),
      send_seconds_(metrics_.AddCounter("send_seconds_total",
                                        "Seconds spent sending segments.")),
      policy_version_(metrics_.AddGauge(
          "policy_version", "Version of the weights the actor acts with.")),
      reconnects_(metrics_.AddCounter("reconnects_total",
                                      "Reconnections to the learner.")),
      env_steps_total_(env_steps_) {}

ActorMetrics::~ActorMetrics() = default;

absl::StatusOr<std::unique_ptr<ActorMetrics>> ActorMetrics::Start(
    const std::string& bind_address, const std::string& auth_token) {
  auto metrics = absl::WrapUnique(new ActorMetrics());
  if (absl::Status status =
          metrics->metrics_.Serve({bind_address, auth_token}, "actor");
      !status.ok()) {
    return status;
  }
  return metrics;
}

int ActorMetrics::port() const { return metrics_.port(); }

void ActorMetrics::RecordEnvSteps(int64_t env_steps_total) {
  std::lock_guard<std::mutex> lock(mutex_);
  env_steps_total_.Record(env_steps_total);
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
