#ifndef VANTAGE_BENCH_CONSUMING_LEARNER_H_
#define VANTAGE_BENCH_CONSUMING_LEARNER_H_

// A learner for the transport benchmarks that only ingests: the real gRPC
// service, gateway (decode and validation), bounded queue and rollout
// stitcher, with no updates, so what it measures is the data path alone.

#include <atomic>
#include <cstdint>
#include <memory>
#include <thread>

#include "absl/status/statusor.h"
#include "learner/ingest/rollout_stitcher.h"
#include "learner/service/actor_gateway.h"
#include "learner/service/learner_service.h"

namespace vantage {

class ConsumingLearner {
 public:
  // Serves on 127.0.0.1 (a free port) an asynchronous run of `run_config`
  // (its horizon and segment length) of `spec` whose version 0 is
  // `weights`. Every `steps_per_version` steps
  // stitched (0: never) it publishes the same weights as the next version,
  // as a learner's updates would, so paced actors go on acting.
  static absl::StatusOr<std::unique_ptr<ConsumingLearner>> Start(
      const pb::RunConfig& run_config, const EnvSpec& spec,
      const PolicyWeights& weights, int64_t steps_per_version);
  ~ConsumingLearner();

  int port() const { return port_; }
  // Env steps stitched so far.
  int64_t consumed_steps() const { return consumed_steps_; }
  GatewayCounters counters() const { return gateway_.counters(); }

 private:
  ConsumingLearner(const pb::RunConfig& run_config, const EnvSpec& spec,
                   PolicyWeights weights, int64_t steps_per_version);
  void Consume();

  SegmentQueue queue_;
  ActorGateway gateway_;
  LearnerService service_;
  RolloutStitcher stitcher_;
  PolicyWeights weights_;
  const int64_t steps_per_version_;
  RunningServer server_;
  int port_ = 0;
  std::atomic<int64_t> consumed_steps_{0};
  std::thread consumer_;
};

}  // namespace vantage

#endif  // VANTAGE_BENCH_CONSUMING_LEARNER_H_
