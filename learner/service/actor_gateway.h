#ifndef VANTAGE_LEARNER_SERVICE_ACTOR_GATEWAY_H_
#define VANTAGE_LEARNER_SERVICE_ACTOR_GATEWAY_H_

// Everything the learner's gRPC service does, without gRPC: actor
// registration, admission of segments into the learner's queue, and the
// board of published weights. The service methods only translate.

#include <condition_variable>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>

#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "common/env/environment.h"
#include "common/nn/policy_weights.h"
#include "common/rollout/segment_queue.h"
#include "proto/run_config.pb.h"
#include "proto/vantage.pb.h"

namespace vantage {

struct GatewayConfig {
  pb::RunConfig run_config;  // resolved; sent to every registering actor
  int64_t max_segment_steps = 4096;
  int64_t max_tensor_bytes = 64 << 20;
  // Segments older than the newest version minus this are dropped and
  // counted (not an error for the actor); -1: any age.
  int64_t max_policy_lag = 0;
  // Ids are never reused within a run: a resumed learner continues after
  // the ids its checkpoint had handed out.
  int64_t first_actor_id = 0;
};

// Why segments were refused, for logs and metrics.
struct GatewayCounters {
  int64_t registrations = 0;
  int64_t accepted_segments = 0;
  int64_t accepted_steps = 0;
  std::map<std::string, int64_t> rejected;  // reason -> segments
};

class ActorGateway {
 public:
  // Admitted segments go to `sink` (which blocks when full: backpressure
  // reaches the actors through their streams).
  ActorGateway(GatewayConfig config, SegmentSink& sink);

  // The first registration fixes the environment spec (unless the run
  // already has one); later ones must match it (InvalidArgument naming the
  // field). Answers once the first weights are published; Unavailable if
  // none arrive within `timeout`.
  absl::StatusOr<pb::RegisterResponse> Register(
      const pb::RegisterRequest& request, absl::Duration timeout);

  // Decodes and validates one segment and hands it to the learner.
  // InvalidArgument (malformed, or wrong for the spec) and
  // FailedPrecondition (unknown actor, a version not published yet) name
  // the problem; too stale a version is dropped with OK and, if `dropped`
  // is not null, *dropped says why (else it is cleared). Every refusal is
  // counted by reason.
  absl::Status Admit(const pb::Segment& segment,
                     std::string* dropped = nullptr);

  // The spec, once known.
  std::optional<EnvSpec> WaitForSpec(absl::Duration timeout);
  // Fixes the spec up front (a resumed run knows it from its checkpoint).
  void SetSpec(const EnvSpec& spec);

  void Publish(const PolicyWeights& weights);
  // The newest weights if newer than `version`, waiting up to `timeout`;
  // null on timeout or once closed.
  std::shared_ptr<const pb::Weights> WaitForWeightsNewerThan(
      int64_t version, absl::Duration timeout);
  int64_t published_version() const;
  // The id the next registration gets (saved in checkpoints).
  int64_t next_actor_id() const;

  // Wakes every waiter; no more registrations or weights.
  void Close();
  bool closed() const;

  GatewayCounters counters() const;

 private:
  absl::Status Reject(const std::string& reason, absl::Status status);

  const GatewayConfig config_;
  SegmentSink& sink_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::optional<EnvSpec> spec_;
  std::set<int64_t> actors_;
  int64_t next_actor_id_ = 0;
  std::shared_ptr<const pb::Weights> weights_;
  bool closed_ = false;
  GatewayCounters counters_;
};

}  // namespace vantage

#endif  // VANTAGE_LEARNER_SERVICE_ACTOR_GATEWAY_H_
