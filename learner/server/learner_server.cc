#include "learner/server/learner_server.h"

#include <malloc.h>

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
#include "learner/run/progress_columns.h"
#include "learner/run/training_run.h"
#include "learner/server/elastic_batch_plan.h"
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

// Says how the pool of live actors compares with the run's own layout
// (distributed.actors x envs_per_actor, this learner's share) once a
// change has lasted kSettle: fewer env slots fill the batch with more
// horizons each (slower), more fill it sooner, none means no update.
class PoolNotice {
 public:
  static constexpr absl::Duration kSettle = absl::Seconds(5);

  explicit PoolNotice(int64_t planned_slots) : planned_(planned_slots) {}

  void Check(const PoolView& pool, absl::Time now = absl::Now()) {
    const int64_t slots = pool.live_env_slots();
    const int64_t actors = static_cast<int64_t>(pool.members.size());
    if (slots != pending_) {
      pending_ = slots;
      since_ = now;
    }
    if (slots == said_ || now - since_ < kSettle) return;
    if (slots == 0) {
      std::fprintf(stderr,
                   "learner: no actor is live (the run plans %ld env slots): "
                   "no update until one registers\n",
                   static_cast<long>(planned_));
    } else {
      std::fprintf(stderr,
                   "learner: %ld actors with %ld env slots are live (the run "
                   "plans %ld)\n",
                   static_cast<long>(actors), static_cast<long>(slots),
                   static_cast<long>(planned_));
    }
    said_ = slots;
  }

 private:
  const int64_t planned_;
  // What was last said, and the live slots seen since `since_`; the run's
  // own layout goes unsaid.
  int64_t said_ = planned_;
  int64_t pending_ = -1;
  absl::Time since_;
};

// The learner process: opens the run (Open), serves actors (Serve), trains
// until the run is done or stopped (Train), and shuts the service down
// (Finish). Members outlive the watcher thread, which Finish joins.
class LearnerProcess {
 public:
  LearnerProcess(const LearnerServerConfig& config,
                 const std::atomic<bool>& stop)
      : config_(config),
        stop_(stop),
        recording_(config.recording),
        own_streams_(config.learner.rollouts_per_batch /
                     std::max(1, config.replicas.world_size)),
        times_({"advantages", "optimisation", "bookkeeping", "publish"}) {
    recording_.record = config.replicas.rank == 0;
  }

  // Checks the configuration, joins the other replicas and opens the run
  // (resumed, or a new directory made before serving so that a taken one
  // fails fast).
  absl::Status Open();
  // The gateway, the gRPC service, the port file, the metrics endpoint and
  // the watcher thread; a failure leaves nothing serving.
  absl::Status Serve();
  // Updates until the run's steps are done or a stop is requested; each
  // update's row goes to `on_update`.
  absl::Status Train(const std::function<void(const ProgressRow&)>& on_update);
  // Stops serving and the watcher; a stop request makes any error OK.
  absl::Status Finish(absl::Status status);

 private:
  LearnerConfig LearnerConfigFor(const EnvSpec& spec) const;
  // The gateway of this learner, its segments `segment_length` steps.
  GatewayConfig GatewayConfigFor(int64_t segment_length) const;
  // The env slots the run plans for this learner (its share of
  // distributed.actors x envs_per_actor).
  int64_t planned_env_slots() const {
    const pb::DistributedSettings& layout = config_.run_config.distributed();
    return static_cast<int64_t>(layout.actors()) * layout.envs_per_actor() /
           std::max(1, config_.replicas.world_size);
  }
  absl::Status RestoreServerState(const std::string& path,
                                  const CheckpointExtras& extras);
  absl::StatusOr<CheckpointExtras> ServerState() const {
    return ServerStateExtras(config_.spec, gateway_->next_actor_id());
  }
  // Writes a checkpoint unless the version has one; says why not if that
  // fails (`when`: the moment, for the message).
  void KeepCheckpoint(const char* when);
  absl::Status StartMetrics();
  // Closing the queue is how a stop request reaches a blocked update; the
  // same thread ends idle streams, expires registrations and keeps the
  // ingest metrics fresh while updates block.
  void Watch();
  void RecordGateway();
  // Expires the actors that stalled, saying who they were.
  void ExpireStalledActors();
  // Frees what the stitcher holds for registrations that expired (the
  // stitcher belongs to the update loop's thread).
  void ForgetExpiredActors();
  void RecordUpdate(const ProgressRow& row, double publish_seconds);

  const LearnerServerConfig& config_;
  const std::atomic<bool>& stop_;
  // Only rank 0 writes the run directory.
  RecordingConfig recording_;
  // This replica's share of the batch.
  const int64_t own_streams_;
  std::shared_ptr<ReplicaGroup> replicas_;
  std::unique_ptr<TrainingRun> run_;
  int64_t first_actor_id_ = 0;
  std::unique_ptr<SegmentQueue> queue_;
  std::unique_ptr<ActorGateway> gateway_;
  std::unique_ptr<LearnerService> service_;
  RunningServer server_;
  std::unique_ptr<LearnerMetrics> metrics_;
  std::thread watcher_;
  std::unique_ptr<ElasticBatchPlan> plan_;
  std::atomic<int64_t> buffered_steps_{0};
  std::mutex expired_mutex_;
  std::vector<int64_t> expired_;
  // Where the learner's time goes, printed when it stops; the rest is
  // waiting for a batch.
  PhaseTimes times_;
};

LearnerConfig LearnerProcess::LearnerConfigFor(const EnvSpec& spec) const {
  LearnerConfig learner_config = config_.learner;
  learner_config.spec = spec;
  learner_config.rollouts_per_batch = own_streams_;
  learner_config.value_limits = config_.limits.values;
  return learner_config;
}

absl::Status LearnerProcess::RestoreServerState(
    const std::string& path, const CheckpointExtras& extras) {
  absl::StatusOr<ServerCheckpointState> state = ReadServerState(path, extras);
  if (!state.ok()) return state.status();
  if (absl::Status same = CheckSameSpec(config_.spec, state->spec);
      !same.ok()) {
    return absl::InvalidArgumentError(
        absl::StrCat(path, " was written for another version of ",
                     config_.spec.name, ": ", same.message()));
  }
  first_actor_id_ = state->next_actor_id;
  return absl::OkStatus();
}

absl::Status LearnerProcess::Open() {
  const int world_size = config_.replicas.world_size;
  if (world_size < 1 || config_.learner.rollouts_per_batch % world_size != 0) {
    return absl::InvalidArgumentError(absl::StrCat(
        "the batch of ", config_.learner.rollouts_per_batch,
        " env streams does not split over ", world_size, " learners"));
  }
  if (absl::Status status = config_.limits.Validate(); !status.ok()) {
    return status;
  }
  absl::StatusOr<std::shared_ptr<ReplicaGroup>> replicas =
      JoinReplicaGroup(config_.replicas);
  if (!replicas.ok()) return replicas.status();
  replicas_ = *std::move(replicas);
  if (world_size > 1) {
    std::fprintf(stderr, "learner: replica %d of %d joined at %s\n",
                 config_.replicas.rank, world_size,
                 config_.replicas.rendezvous.c_str());
  }
  absl::StatusOr<std::unique_ptr<TrainingRun>> run = TrainingRun::Open(
      recording_, LearnerConfigFor(config_.spec),
      [this](const std::string& path, const CheckpointExtras& extras) {
        return RestoreServerState(path, extras);
      },
      replicas_);
  if (!run.ok()) return run.status();
  run_ = *std::move(run);
  if (config_.eval_every > 0 && config_.evaluate && recording_.record) {
    if (absl::Status status = run_->EvaluateEvery(
            config_.eval_every, config_.evaluate, /*in_background=*/true);
        !status.ok()) {
      return status;
    }
  }
  if (recording_.resume) {
    std::fprintf(stderr,
                 "learner: resuming %s from policy version %ld (%ld env "
                 "steps)\n",
                 recording_.run_dir.c_str(),
                 static_cast<long>(run_->learner().policy_version()),
                 static_cast<long>(run_->learner().env_steps()));
  }
  return absl::OkStatus();
}

GatewayConfig LearnerProcess::GatewayConfigFor(int64_t segment_length) const {
  const pb::DistributedSettings& layout = config_.run_config.distributed();
  GatewayConfig gateway;
  gateway.run_config = config_.run_config;
  gateway.max_segment_steps = segment_length;
  gateway.max_policy_lag = layout.max_policy_lag();
  gateway.first_actor_id = first_actor_id_;
  gateway.spec = config_.spec;
  gateway.core_state_size = config_.learner.network.core_state_size();
  gateway.limits = config_.limits;
  gateway.batch_rollouts = own_streams_;
  // An actor paces whole horizons of whole segments.
  gateway.horizon_steps =
      std::max<int64_t>(
          1, config_.learner.horizon / std::max<int64_t>(1, segment_length)) *
      segment_length;
  gateway.lead =
      layout.sync() ? 0 : std::min<int64_t>(2, layout.max_policy_lag());
  gateway.stall_timeout = layout.has_actor_stall_timeout_s()
                              ? absl::Seconds(layout.actor_stall_timeout_s())
                              : absl::ZeroDuration();
  return gateway;
}

absl::Status LearnerProcess::Serve() {
  const pb::RunConfig& run_config = config_.run_config;
  const int64_t segment_length = run_config.training().segment_length();
  // Room for two whole batches: asynchronous actors keep acting for the
  // next batch while an update runs (which is how acting hides behind
  // learning), and actors that outpace the learner beyond that block on
  // their streams instead of growing memory.
  const int64_t batch_segments =
      own_streams_ *
      (config_.learner.horizon / std::max<int64_t>(1, segment_length));
  // The gateway checks every segment it queues, for its sender to hear why.
  queue_ = std::make_unique<SegmentQueue>(
      static_cast<size_t>(std::max<int64_t>(8, 2 * batch_segments)),
      /*checked=*/true);
  gateway_ =
      std::make_unique<ActorGateway>(GatewayConfigFor(segment_length), *queue_);
  const pb::DistributedSettings& layout = run_config.distributed();
  plan_ = std::make_unique<ElasticBatchPlan>(
      *gateway_, layout.sync(), own_streams_, planned_env_slots(),
      [this] { return static_cast<int64_t>(queue_->size()); });
  run_->learner().SetBatchPlan(plan_.get());
  // Nothing larger than the run's largest valid segment is ever read.
  ServiceLimits service_limits = config_.service_limits;
  service_limits.max_segment_message_bytes = MaxSegmentMessageBytes(
      config_.spec, segment_length, config_.learner.network.core_state_size());
  service_ = std::make_unique<LearnerService>(*gateway_, service_limits);
  ServerOptions options;
  options.listen = config_.listen;
  options.security = config_.security;
  options.max_receive_message_bytes =
      std::max(service_limits.max_segment_message_bytes,
               service_limits.max_request_bytes);
  options.max_threads = config_.max_server_threads;
  options.max_memory_bytes = config_.max_grpc_memory_bytes;
  absl::StatusOr<RunningServer> server = StartServer(options, *service_);
  if (!server.ok()) return server.status();
  server_ = *std::move(server);
  std::fprintf(stderr, "learner: serving on port %d\n", server_.port);
  absl::Status status = config_.port_file.empty()
                            ? absl::OkStatus()
                            : WritePortFile(config_.port_file, server_.port);
  if (status.ok()) status = StartMetrics();
  if (!status.ok()) {
    server_.server->Shutdown();
    return status;
  }
  watcher_ = std::thread([this] { Watch(); });
  return absl::OkStatus();
}

absl::Status LearnerProcess::StartMetrics() {
  if (config_.metrics_address.empty()) return absl::OkStatus();
  absl::StatusOr<std::unique_ptr<LearnerMetrics>> started =
      LearnerMetrics::Start(config_.metrics_address,
                            config_.security.auth_token);
  if (!started.ok()) return started.status();
  metrics_ = *std::move(started);
  metrics_->SetMaxPolicyLag(config_.run_config.distributed().max_policy_lag());
  std::fprintf(stderr, "learner: metrics on port %d\n", metrics_->port());
  if (config_.metrics_port_file.empty()) return absl::OkStatus();
  return WritePortFile(config_.metrics_port_file, metrics_->port());
}

void LearnerProcess::Watch() {
  PoolNotice notice(planned_env_slots());
  int64_t ticks = 0;
  while (!stop_ && !gateway_->closed()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    // gRPC holds a message whole before it checks its size, and glibc
    // keeps the freed pages of a refused 200 MB message resident; give them
    // back every 10 s.
    if (++ticks % 200 == 0) malloc_trim(0);
    notice.Check(gateway_->Pool());
    service_->CancelIdleStreams();
    ExpireStalledActors();
    std::vector<int64_t> gone = gateway_->ExpireIdle();
    if (!gone.empty()) {
      std::lock_guard<std::mutex> lock(expired_mutex_);
      expired_.insert(expired_.end(), gone.begin(), gone.end());
    }
    RecordGateway();
  }
  queue_->Close();
}

void LearnerProcess::ExpireStalledActors() {
  for (const StalledActor& actor : gateway_->ExpireStalled()) {
    std::fprintf(
        stderr,
        "learner: actor %ld (%s at %s, env %s) owed %ld steps and sent none "
        "for %s (--actor_stall_timeout_s); its registration expires and the "
        "batch goes on without it\n",
        static_cast<long>(actor.actor_id), actor.name.c_str(),
        actor.peer.c_str(), config_.spec.name.c_str(),
        static_cast<long>(actor.owed_steps),
        absl::FormatDuration(absl::Trunc(actor.silent, absl::Seconds(1)))
            .c_str());
  }
}

void LearnerProcess::RecordGateway() {
  if (metrics_ == nullptr) return;
  const GatewayCounters counters = gateway_->counters();
  metrics_->RecordSegmentsAccepted(counters.accepted_segments);
  metrics_->RecordRejected(counters.rejected);
  const PoolView pool = gateway_->Pool();
  metrics_->RecordActors({counters.live_actors, service_->open_streams(),
                          counters.registrations, counters.expirations,
                          counters.stalls, pool.live_env_slots(),
                          pool.horizons});
  metrics_->SetQueueDepth(static_cast<int64_t>(queue_->size()),
                          buffered_steps_.load());
  std::vector<LearnerMetrics::ActorActivity> actors;
  const absl::Time now = absl::Now();
  for (const ActorActivity& actor : gateway_->activity()) {
    // An open stream is an actor heard from now, even one that waits for
    // room in the queue.
    const absl::Time seen = actor.connected ? now : actor.last_seen;
    actors.push_back({actor.actor_id, actor.accepted_steps,
                      absl::ToDoubleSeconds(seen - absl::UnixEpoch())});
  }
  metrics_->RecordActorActivity(actors);
}

void LearnerProcess::KeepCheckpoint(const char* when) {
  if (absl::Status status =
          run_->CheckpointNow([this] { return ServerState(); });
      !status.ok()) {
    std::fprintf(stderr, "learner: no checkpoint %s: %s\n", when,
                 std::string(status.message()).c_str());
  }
}

void LearnerProcess::ForgetExpiredActors() {
  std::lock_guard<std::mutex> lock(expired_mutex_);
  for (int64_t actor_id : expired_) run_->learner().ForgetActor(actor_id);
  expired_.clear();
}

void LearnerProcess::RecordUpdate(const ProgressRow& row,
                                  double publish_seconds) {
  // Bookkeeping: the update's statistics and checks. Waiting is the rest:
  // for a batch, and writing checkpoints.
  const UpdateStats& stats = row.stats;
  times_.Add(0, stats.advantage_seconds);
  times_.Add(1, stats.optimisation_seconds);
  times_.Add(2, stats.update_seconds - stats.advantage_seconds -
                    stats.optimisation_seconds);
  times_.Add(3, publish_seconds);
  buffered_steps_ = run_->learner().buffered_steps();
  if (metrics_ == nullptr) return;
  // The statistics first: a scrape that sees this update's version finds
  // its statistics' series.
  std::vector<LearnerMetrics::Statistic> statistics;
  for (const ProgressColumn& column : ProgressColumns()) {
    statistics.push_back({column.metric, column.help, column.value(row),
                          column.kind == ProgressColumn::Metric::kCounter});
  }
  metrics_->RecordStatistics(statistics);
  for (int64_t lag : stats.rollout_policy_lags) {
    metrics_->RecordPolicyLag(lag);
  }
  metrics_->RecordUpdate(stats.policy_version, stats.update_seconds);
  metrics_->AddUpdatePhases(stats.advantage_seconds, stats.optimisation_seconds,
                            publish_seconds);
  RecordGateway();
}

absl::Status LearnerProcess::Train(
    const std::function<void(const ProgressRow&)>& on_update) {
  LearnerCore& learner = run_->learner();
  gateway_->Publish(learner.CurrentWeights());
  while (!run_->done() && !stop_) {
    absl::StatusOr<ProgressRow> row =
        run_->Update(*queue_, [this] { return ServerState(); });
    if (!row.ok() && stop_) break;
    if (!row.ok()) {
      // A replica is gone and the update was undone: what the learner
      // holds is the last update's state, worth keeping for the restart.
      if (absl::IsUnavailable(row.status())) {
        KeepCheckpoint("after the failure");
      }
      return row.status();
    }
    const auto publish_start = std::chrono::steady_clock::now();
    gateway_->Publish(learner.CurrentWeights());
    const double publish_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() -
                                      publish_start)
            .count();
    ForgetExpiredActors();
    RecordUpdate(*row, publish_seconds);
    on_update(*row);
  }
  if (stop_) {
    // Stopped by a signal (a scheduler's preemption): keep every update.
    KeepCheckpoint("at the stop");
  } else {
    // Complete: the actors are told so (and exit), rather than finding the
    // learner gone and reconnecting to it forever.
    gateway_->FinishRun();
  }
  return absl::OkStatus();
}

absl::Status LearnerProcess::Finish(absl::Status status) {
  std::fprintf(stderr, "learner: %s\n",
               times_.Summary("waiting for data").c_str());
  gateway_->Close();
  queue_->Close();
  server_.server->Shutdown(std::chrono::system_clock::now() +
                           std::chrono::seconds(2));
  watcher_.join();
  return stop_ ? absl::OkStatus() : status;
}

}  // namespace

absl::Status RunLearnerServer(
    const LearnerServerConfig& config, const std::atomic<bool>& stop,
    const std::function<void(const ProgressRow&)>& on_update) {
  LearnerProcess process(config, stop);
  if (absl::Status status = process.Open(); !status.ok()) return status;
  if (absl::Status status = process.Serve(); !status.ok()) return status;
  return process.Finish(process.Train(on_update));
}

}  // namespace vantage
