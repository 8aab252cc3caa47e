#include "bench/consuming_learner.h"

#include <chrono>
#include <utility>

#include "actor/run_settings.h"

namespace vantage {
namespace {

GatewayConfig MakeGatewayConfig(const pb::RunConfig& run_config,
                                const EnvSpec& spec) {
  GatewayConfig config;
  config.run_config = run_config;
  config.spec = spec;
  if (absl::StatusOr<NetworkConfig> network = PolicyNetworkOf(run_config);
      network.ok()) {
    config.core_state_size = network->core_state_size();
  }
  config.run_config.mutable_distributed()->set_sync(false);
  config.max_segment_steps = run_config.training().segment_length();
  config.max_policy_lag = -1;  // nothing is too stale to be ingested
  return config;
}

}  // namespace

ConsumingLearner::ConsumingLearner(const pb::RunConfig& run_config,
                                   const EnvSpec& spec, PolicyWeights weights,
                                   int64_t steps_per_version)
    : queue_(64),
      gateway_(MakeGatewayConfig(run_config, spec), queue_),
      service_(gateway_),
      stitcher_(run_config.training().horizon()),
      weights_(std::move(weights)),
      steps_per_version_(steps_per_version) {}

absl::StatusOr<std::unique_ptr<ConsumingLearner>> ConsumingLearner::Start(
    const pb::RunConfig& run_config, const EnvSpec& spec,
    const PolicyWeights& weights, int64_t steps_per_version) {
  std::unique_ptr<ConsumingLearner> learner(
      new ConsumingLearner(run_config, spec, weights, steps_per_version));
  learner->gateway_.Publish(learner->weights_);
  absl::StatusOr<RunningServer> server =
      StartServer(ServerOptions(), learner->service_);
  if (!server.ok()) return server.status();
  learner->server_ = *std::move(server);
  learner->port_ = learner->server_.port;
  learner->consumer_ = std::thread([raw = learner.get()] { raw->Consume(); });
  return learner;
}

ConsumingLearner::~ConsumingLearner() {
  gateway_.Close();
  queue_.Close();
  if (server_.server != nullptr) {
    server_.server->Shutdown(std::chrono::system_clock::now() +
                             std::chrono::seconds(1));
  }
  if (consumer_.joinable()) consumer_.join();
}

void ConsumingLearner::Consume() {
  while (true) {
    absl::StatusOr<Segment> segment = queue_.Receive();
    if (!segment.ok()) return;
    const int64_t steps = segment->steps();
    if (!stitcher_.Add(*std::move(segment)).ok()) continue;
    const int64_t before = consumed_steps_.fetch_add(steps);
    // Finished rollouts would go to an update; here they are dropped.
    (void)stitcher_.TakeReady();
    if (steps_per_version_ > 0 &&
        (before + steps) / steps_per_version_ > before / steps_per_version_) {
      ++weights_.version;
      gateway_.Publish(weights_);
    }
  }
}

}  // namespace vantage
