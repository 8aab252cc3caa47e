#include "deploy/learner_server.h"

#include <chrono>
#include <cstdio>
#include <fstream>
#include <thread>

#include "absl/strings/str_cat.h"
#include "deploy/run_recorder.h"
#include "learner/service/actor_gateway.h"
#include "learner/service/learner_metrics.h"
#include "learner/service/learner_service.h"

namespace vantage {
namespace {

absl::Status WritePortFile(const std::string& path, int port) {
  const std::string temporary = path + ".tmp";
  {
    std::ofstream file(temporary, std::ios::trunc);
    file << port << "\n";
    if (!file.flush()) {
      return absl::InternalError(absl::StrCat("cannot write ", temporary));
    }
  }
  if (std::rename(temporary.c_str(), path.c_str()) != 0) {
    return absl::InternalError(absl::StrCat("cannot write ", path));
  }
  return absl::OkStatus();
}

}  // namespace

absl::Status RunLearnerServer(
    const LearnerServerConfig& config, const std::atomic<bool>& stop,
    const std::function<void(const ProgressRow&)>& on_update) {
  const LocalTrainingConfig& training = config.training;
  // Room for a few rounds of every stream: actors that outpace the learner
  // block on their streams instead of growing memory.
  SegmentQueue queue(static_cast<size_t>(std::max(8, 4 * training.num_envs)));
  GatewayConfig gateway_config;
  gateway_config.run_config = config.run_config;
  gateway_config.max_segment_steps = config.run_config.segment_length();
  gateway_config.max_policy_lag = config.run_config.max_policy_lag();
  ActorGateway gateway(gateway_config, queue);
  LearnerService service(gateway);
  ServerOptions options;
  options.listen = config.listen;
  options.security = config.security;
  absl::StatusOr<RunningServer> server = StartServer(options, service);
  if (!server.ok()) return server.status();
  std::fprintf(stderr, "learner: serving on port %d\n", server->port);
  if (!config.port_file.empty()) {
    if (absl::Status status = WritePortFile(config.port_file, server->port);
        !status.ok()) {
      return status;
    }
  }
  std::unique_ptr<LearnerMetrics> metrics;
  if (!config.metrics_address.empty()) {
    absl::StatusOr<std::unique_ptr<LearnerMetrics>> started =
        LearnerMetrics::Start(config.metrics_address);
    if (!started.ok()) {
      server->server->Shutdown();
      return started.status();
    }
    metrics = *std::move(started);
    std::fprintf(stderr, "learner: metrics on port %d\n", metrics->port());
  }
  auto record_gateway = [&] {
    if (metrics == nullptr) return;
    const GatewayCounters counters = gateway.counters();
    metrics->RecordSegmentsAccepted(counters.accepted_segments);
    metrics->RecordRejected(counters.rejected);
    metrics->SetActorsRegistered(counters.registrations);
    metrics->SetQueueDepth(static_cast<int64_t>(queue.size()), 0);
  };
  // Closing the queue is how a stop request reaches a blocked update; the
  // same thread keeps the ingest metrics fresh while updates block.
  std::thread watcher([&] {
    while (!stop && !gateway.closed()) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      record_gateway();
    }
    queue.Close();
  });
  auto finish = [&](absl::Status status) {
    gateway.Close();
    queue.Close();
    server->server->Shutdown(std::chrono::system_clock::now() +
                             std::chrono::seconds(2));
    watcher.join();
    return stop ? absl::OkStatus() : status;
  };

  std::optional<EnvSpec> spec;
  while (!spec.has_value() && !stop) {
    spec = gateway.WaitForSpec(absl::Milliseconds(200));
  }
  if (!spec.has_value()) return finish(absl::OkStatus());
  LearnerConfig learner_config = MakeLearnerConfig(training, *spec);
  learner_config.max_segment_steps = config.run_config.segment_length();
  absl::StatusOr<std::unique_ptr<LearnerCore>> learner =
      LearnerCore::Create(learner_config);
  if (!learner.ok()) return finish(learner.status());
  std::optional<RunDirectory> run;
  if (!training.run_dir.empty()) {
    absl::StatusOr<RunDirectory> created =
        RunDirectory::Create(training.run_dir, training.config_json);
    if (!created.ok()) return finish(created.status());
    run = *std::move(created);
  }
  RecorderConfig recorder_config;
  recorder_config.config_json = training.config_json;
  recorder_config.checkpoint_every = training.checkpoint_every;
  recorder_config.keep_checkpoints = training.keep_checkpoints;
  recorder_config.total_env_steps = training.total_env_steps;
  RunRecorder recorder(std::move(run), recorder_config);

  gateway.Publish((*learner)->CurrentWeights());
  while ((*learner)->env_steps() < training.total_env_steps && !stop) {
    absl::StatusOr<UpdateStats> stats = (*learner)->RunUpdate(queue);
    if (!stats.ok()) return finish(stop ? absl::OkStatus() : stats.status());
    gateway.Publish((*learner)->CurrentWeights());
    absl::StatusOr<ProgressRow> row = recorder.Record(**learner, *stats, [] {
      return absl::StatusOr<CheckpointExtras>(CheckpointExtras());
    });
    if (!row.ok()) return finish(row.status());
    if (metrics != nullptr) {
      for (int64_t lag : stats->rollout_policy_lags) {
        metrics->RecordPolicyLag(lag);
      }
      metrics->RecordUpdate(stats->policy_version, stats->env_steps,
                            stats->episodes, stats->update_seconds,
                            row->mean_return, row->steps_per_second);
      record_gateway();
    }
    on_update(*row);
  }
  return finish(absl::OkStatus());
}

}  // namespace vantage
