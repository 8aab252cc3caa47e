#include "deploy/learner_server.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <mutex>
#include <thread>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/time/clock.h"
#include "absl/time/time.h"
#include "common/net/port_file.h"
#include "common/util/phase_times.h"
#include "deploy/progress_columns.h"
#include "deploy/training_run.h"
#include "learner/service/actor_gateway.h"
#include "learner/service/learner_metrics.h"
#include "learner/service/learner_service.h"
#include "proto/wire_format.h"

namespace vantage {
namespace {

constexpr char kEnvSpec[] = "env_spec";
constexpr char kNextActorId[] = "next_actor_id";

// What a learner server keeps in its checkpoints besides the learner: the
// environment's whole spec (a resumed learner answers registrations before
// any actor has told it) and the next actor id.
struct ServerCheckpointState {
  EnvSpec spec;
  int64_t next_actor_id = 0;
};

CheckpointExtras ServerStateExtras(const EnvSpec& spec, int64_t next_actor_id) {
  pb::EnvSpec proto;
  EnvSpecToProto(spec, &proto);
  return {{kEnvSpec, proto.SerializeAsString()},
          {kNextActorId, absl::StrCat(next_actor_id)}};
}

absl::StatusOr<ServerCheckpointState> ReadServerState(
    const std::string& path, const CheckpointExtras& extras) {
  auto spec_bytes = extras.find(kEnvSpec);
  auto next_id = extras.find(kNextActorId);
  if (spec_bytes == extras.end() || next_id == extras.end()) {
    return absl::InvalidArgumentError(absl::StrCat(
        path,
        " holds no learner-server state (a checkpoint of a local run "
        "resumes with --mode=local)"));
  }
  pb::EnvSpec proto;
  if (!proto.ParseFromString(spec_bytes->second)) {
    return absl::DataLossError(absl::StrCat(path, ": unreadable env_spec"));
  }
  absl::StatusOr<EnvSpec> spec = EnvSpecFromProto(proto);
  if (!spec.ok()) return spec.status();
  ServerCheckpointState state;
  state.spec = *std::move(spec);
  if (!absl::SimpleAtoi(next_id->second, &state.next_actor_id) ||
      state.next_actor_id < 0) {
    return absl::DataLossError(absl::StrCat(path, ": bad next_actor_id"));
  }
  return state;
}

// A sync learner takes each update's rollouts from every env stream of its
// batch, so with fewer streams registered it waits without end: said once
// per shortfall that lasts kGrace (actors take a moment to register), and
// always in the missing_env_slots series.
class EnvSlotShortfall {
 public:
  static constexpr absl::Duration kGrace = absl::Seconds(10);

  EnvSlotShortfall(bool sync, int64_t needed) : sync_(sync), needed_(needed) {}

  // The streams missing now, given those of the registered actors.
  int64_t Check(int64_t live_env_slots, absl::Time now = absl::Now()) {
    const int64_t missing =
        sync_ ? std::max<int64_t>(0, needed_ - live_env_slots) : 0;
    if (missing == 0) {
      if (said_) {
        std::fprintf(stderr,
                     "learner: all %ld env streams of the batch are "
                     "registered again\n",
                     static_cast<long>(needed_));
      }
      since_ = absl::InfiniteFuture();
      said_ = false;
      return 0;
    }
    if (since_ == absl::InfiniteFuture()) since_ = now;
    if (!said_ && now - since_ >= kGrace) {
      std::fprintf(stderr,
                   "learner: a sync update takes a rollout from each of %ld "
                   "env streams and the registered actors have %ld: no "
                   "update until %ld more register\n",
                   static_cast<long>(needed_),
                   static_cast<long>(live_env_slots),
                   static_cast<long>(missing));
      said_ = true;
    }
    return missing;
  }

 private:
  const bool sync_;
  const int64_t needed_;
  absl::Time since_ = absl::InfiniteFuture();
  bool said_ = false;
};

}  // namespace

absl::Status RunLearnerServer(
    const LearnerServerConfig& config, const std::atomic<bool>& stop,
    const std::function<void(const ProgressRow&)>& on_update) {
  const int world_size = config.replicas.world_size;
  if (world_size < 1 || config.training.num_envs % world_size != 0) {
    return absl::InvalidArgumentError(absl::StrCat(
        "the batch of ", config.training.num_envs,
        " env streams does not split over ", world_size, " learners"));
  }
  LocalTrainingConfig training = config.training;
  training.record = config.replicas.rank == 0;
  // This replica's share of the batch.
  const int64_t own_streams = training.num_envs / world_size;
  auto learner_config_for = [&](const EnvSpec& spec) {
    LearnerConfig learner_config = MakeLearnerConfig(training, spec);
    learner_config.rollouts_per_batch = own_streams;
    learner_config.max_segment_steps =
        config.run_config.training().segment_length();
    learner_config.value_limits = config.limits.values;
    return learner_config;
  };
  if (absl::Status status = config.limits.Validate(); !status.ok()) {
    return status;
  }
  const EnvSpec& spec = config.spec;
  absl::StatusOr<std::shared_ptr<ReplicaGroup>> replicas =
      JoinReplicaGroup(config.replicas);
  if (!replicas.ok()) return replicas.status();
  if (world_size > 1) {
    std::fprintf(stderr, "learner: replica %d of %d joined at %s\n",
                 config.replicas.rank, world_size,
                 config.replicas.rendezvous.c_str());
  }
  // A resumed run knows its learner and the actor ids it handed out before
  // any actor registers; a new run's directory is made before serving, so a
  // taken one fails fast.
  int64_t first_actor_id = 0;
  absl::StatusOr<std::unique_ptr<TrainingRun>> run = TrainingRun::Open(
      training, learner_config_for(spec),
      [&](const std::string& path, const CheckpointExtras& extras) {
        absl::StatusOr<ServerCheckpointState> state =
            ReadServerState(path, extras);
        if (!state.ok()) return state.status();
        if (absl::Status same = CheckSameSpec(spec, state->spec); !same.ok()) {
          return absl::InvalidArgumentError(
              absl::StrCat(path, " was written for another version of ",
                           spec.name, ": ", same.message()));
        }
        first_actor_id = state->next_actor_id;
        return absl::OkStatus();
      },
      *replicas);
  if (!run.ok()) return run.status();
  LearnerCore& learner = (*run)->learner();
  if (training.resume) {
    std::fprintf(stderr,
                 "learner: resuming %s from policy version %ld (%ld env "
                 "steps)\n",
                 training.run_dir.c_str(),
                 static_cast<long>(learner.policy_version()),
                 static_cast<long>(learner.env_steps()));
  }

  // Room for two whole batches: asynchronous actors keep acting for the
  // next batch while an update runs (which is how acting hides behind
  // learning), and actors that outpace the learner beyond that block on
  // their streams instead of growing memory.
  const int64_t batch_segments =
      own_streams *
      (training.learner.horizon /
       std::max<int64_t>(1, config.run_config.training().segment_length()));
  SegmentQueue queue(
      static_cast<size_t>(std::max<int64_t>(8, 2 * batch_segments)));
  GatewayConfig gateway_config;
  gateway_config.run_config = config.run_config;
  gateway_config.max_segment_steps =
      config.run_config.training().segment_length();
  gateway_config.max_policy_lag =
      config.run_config.distributed().max_policy_lag();
  gateway_config.first_actor_id = first_actor_id;
  gateway_config.spec = spec;
  gateway_config.limits = config.limits;
  ActorGateway gateway(gateway_config, queue);
  // Nothing larger than the run's largest valid segment is ever read.
  ServiceLimits service_limits = config.service_limits;
  service_limits.max_segment_message_bytes = MaxSegmentMessageBytes(
      spec, config.run_config.training().segment_length());
  LearnerService service(gateway, service_limits);
  ServerOptions options;
  options.listen = config.listen;
  options.security = config.security;
  options.max_receive_message_bytes =
      std::max(service_limits.max_segment_message_bytes,
               service_limits.max_request_bytes);
  options.max_threads = config.max_server_threads;
  options.max_memory_bytes = config.max_grpc_memory_bytes;
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
        LearnerMetrics::Start(config.metrics_address,
                              config.security.auth_token);
    if (!started.ok()) {
      server->server->Shutdown();
      return started.status();
    }
    metrics = *std::move(started);
    metrics->SetMaxPolicyLag(config.run_config.distributed().max_policy_lag());
    std::fprintf(stderr, "learner: metrics on port %d\n", metrics->port());
    if (!config.metrics_port_file.empty()) {
      if (absl::Status status =
              WritePortFile(config.metrics_port_file, metrics->port());
          !status.ok()) {
        server->server->Shutdown();
        return status;
      }
    }
  }
  std::atomic<int64_t> buffered_steps{0};
  std::atomic<int64_t> missing_env_slots{0};
  auto record_gateway = [&] {
    if (metrics == nullptr) return;
    const GatewayCounters counters = gateway.counters();
    metrics->RecordSegmentsAccepted(counters.accepted_segments);
    metrics->RecordRejected(counters.rejected);
    metrics->RecordActors({counters.live_actors, service.open_streams(),
                           counters.registrations, counters.expirations,
                           missing_env_slots.load()});
    metrics->SetQueueDepth(static_cast<int64_t>(queue.size()),
                           buffered_steps.load());
    std::vector<LearnerMetrics::ActorActivity> actors;
    const absl::Time now = absl::Now();
    for (const ActorActivity& actor : gateway.activity()) {
      // An open stream is an actor heard from now, even one that waits
      // for room in the queue.
      const absl::Time seen = actor.connected ? now : actor.last_seen;
      actors.push_back({actor.actor_id, actor.accepted_steps,
                        absl::ToDoubleSeconds(seen - absl::UnixEpoch())});
    }
    metrics->RecordActorActivity(actors);
  };
  // Registrations that expired, for the update loop to free (the stitcher
  // belongs to that thread).
  std::mutex expired_mutex;
  std::vector<int64_t> expired;
  // Closing the queue is how a stop request reaches a blocked update; the
  // same thread ends idle streams, expires registrations and keeps the
  // ingest metrics fresh while updates block.
  std::thread watcher([&] {
    EnvSlotShortfall shortfall(config.run_config.distributed().sync(),
                               own_streams);
    while (!stop && !gateway.closed()) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      missing_env_slots = shortfall.Check(gateway.counters().live_env_slots);
      service.CancelIdleStreams();
      std::vector<int64_t> gone = gateway.ExpireIdle();
      if (!gone.empty()) {
        std::lock_guard<std::mutex> lock(expired_mutex);
        expired.insert(expired.end(), gone.begin(), gone.end());
      }
      record_gateway();
    }
    queue.Close();
  });
  // Where the learner's time goes, printed when it stops; the rest is
  // waiting for a batch.
  PhaseTimes times({"advantages", "optimisation", "bookkeeping", "publish"});
  auto finish = [&](absl::Status status) {
    std::fprintf(stderr, "learner: %s\n",
                 times.Summary("waiting for data").c_str());
    gateway.Close();
    queue.Close();
    server->server->Shutdown(std::chrono::system_clock::now() +
                             std::chrono::seconds(2));
    watcher.join();
    return stop ? absl::OkStatus() : status;
  };

  auto server_state = [&]() -> absl::StatusOr<CheckpointExtras> {
    return ServerStateExtras(spec, gateway.next_actor_id());
  };

  gateway.Publish(learner.CurrentWeights());
  while (!(*run)->done() && !stop) {
    absl::StatusOr<ProgressRow> row = (*run)->Update(queue, server_state);
    if (!row.ok() && stop) break;
    if (!row.ok() && absl::IsUnavailable(row.status())) {
      // A replica is gone and the update was undone: what the learner
      // holds is the last update's state, worth keeping for the restart.
      if (absl::Status kept = (*run)->CheckpointNow(server_state); !kept.ok()) {
        std::fprintf(stderr, "learner: no checkpoint after the failure: %s\n",
                     std::string(kept.message()).c_str());
      }
    }
    if (!row.ok()) return finish(row.status());
    const auto publish_start = std::chrono::steady_clock::now();
    gateway.Publish(learner.CurrentWeights());
    const double publish_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() -
                                      publish_start)
            .count();
    // Bookkeeping: the update's statistics and checks. Waiting is the rest:
    // for a batch, and writing checkpoints.
    const UpdateStats& update = row->stats;
    times.Add(0, update.advantage_seconds);
    times.Add(1, update.optimisation_seconds);
    times.Add(2, update.update_seconds - update.advantage_seconds -
                     update.optimisation_seconds);
    times.Add(3, publish_seconds);
    {
      std::lock_guard<std::mutex> lock(expired_mutex);
      for (int64_t actor_id : expired) learner.ForgetActor(actor_id);
      expired.clear();
    }
    buffered_steps = learner.buffered_steps();
    if (metrics != nullptr) {
      const UpdateStats& stats = row->stats;
      // The statistics first: a scrape that sees this update's version
      // finds its statistics' series.
      std::vector<LearnerMetrics::Statistic> statistics;
      for (const ProgressColumn& column : ProgressColumns()) {
        statistics.push_back({column.metric, column.help, column.value(*row),
                              column.kind == ProgressColumn::Metric::kCounter});
      }
      metrics->RecordStatistics(statistics);
      for (int64_t lag : stats.rollout_policy_lags) {
        metrics->RecordPolicyLag(lag);
      }
      metrics->RecordUpdate(stats.policy_version, stats.update_seconds);
      metrics->AddUpdatePhases(stats.advantage_seconds,
                               stats.optimisation_seconds, publish_seconds);
      record_gateway();
    }
    on_update(*row);
  }
  // Stopped by a signal (a scheduler's preemption): keep every update.
  if (stop) {
    if (absl::Status status = (*run)->CheckpointNow(server_state);
        !status.ok()) {
      std::fprintf(stderr, "learner: no checkpoint at the stop: %s\n",
                   std::string(status.message()).c_str());
    }
  } else {
    // Complete: the actors are told so (and exit), rather than finding
    // the learner gone and reconnecting to it forever.
    gateway.FinishRun();
  }
  return finish(absl::OkStatus());
}

}  // namespace vantage
