#include "actor/remote/remote_actor.h"

#include <grpcpp/grpcpp.h>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <mutex>
#include <thread>

#include "absl/strings/str_cat.h"
#include "absl/time/clock.h"
#include "absl/time/time.h"
#include "actor/actor_core.h"
#include "actor/envs/env_registry.h"
#include "actor/remote/actor_metrics.h"
#include "actor/remote/round_watchdog.h"
#include "actor/run_settings.h"
#include "common/net/grpc_security.h"
#include "common/net/keepalive.h"
#include "common/net/port_file.h"
#include "common/rollout/horizon_pacer.h"
#include "common/util/phase_times.h"
#include "common/util/split_mix.h"
#include "proto/vantage.grpc.pb.h"
#include "proto/wire_format.h"

namespace vantage {
namespace {

absl::Status FromGrpc(const grpc::Status& status, absl::string_view what) {
  if (status.ok()) return absl::OkStatus();
  return absl::Status(static_cast<absl::StatusCode>(status.error_code()),
                      absl::StrCat(what, ": ", status.error_message()));
}

// Refusals that no retry can mend (an expired registration, NOT_FOUND, is
// mended by registering again).
bool IsRefusal(const absl::Status& status) {
  return absl::IsInvalidArgument(status) || absl::IsUnauthenticated(status) ||
         absl::IsPermissionDenied(status);
}

// How long a session whose segment stream the learner cut waits for the
// subscription to say whether the run is over.
constexpr absl::Duration kRunOverGrace = absl::Seconds(3);

// What each env slot may act with a version (a learner that predates the
// grant allows one horizon).
int64_t GrantedHorizons(const pb::Weights& weights) {
  return weights.has_horizons() ? weights.horizons() : 1;
}

// The phases of the actor's time split.
constexpr size_t kInferencePhase = 0;
constexpr size_t kPhysicsPhase = 1;
constexpr size_t kSendPhase = 2;

// Segments onto an open client stream.
class StreamSink : public SegmentSink {
 public:
  StreamSink(grpc::ClientWriter<pb::Segment>& writer, ActorMetrics* metrics,
             PhaseTimes& times, RoundWatchdog& watchdog)
      : writer_(writer),
        metrics_(metrics),
        times_(times),
        watchdog_(watchdog) {}
  absl::Status Send(Segment segment) override {
    const auto start = std::chrono::steady_clock::now();
    pb::Segment proto;
    SegmentToProto(segment, &proto);
    watchdog_.Idle();
    const bool written = writer_.Write(proto);
    watchdog_.Busy();
    if (!written) {
      return absl::UnavailableError("the learner closed the segment stream");
    }
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
            .count();
    times_.Add(kSendPhase, seconds);
    if (metrics_ != nullptr) {
      metrics_->AddSegmentsSent(1);
      metrics_->AddSendSeconds(seconds);
    }
    return absl::OkStatus();
  }

 private:
  grpc::ClientWriter<pb::Segment>& writer_;
  ActorMetrics* metrics_;
  PhaseTimes& times_;
  RoundWatchdog& watchdog_;
};

// The newest weights a subscription delivered.
class WeightsSlot {
 public:
  // A newer version, or the same one with another grant of horizons.
  void Put(pb::Weights weights) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (weights_ == nullptr || weights.version() > weights_->version() ||
        (weights.version() == weights_->version() &&
         GrantedHorizons(weights) != GrantedHorizons(*weights_))) {
      weights_ = std::make_shared<pb::Weights>(std::move(weights));
    }
  }
  std::shared_ptr<const pb::Weights> Get() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return weights_;
  }
  // The subscription ended with `status` (how the learner finished it).
  void End(absl::Status status) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      end_status_ = std::move(status);
    }
    ended_ = true;
  }
  bool ended() const { return ended_; }
  // Until the subscription ends or `timeout` passes; whether it ended.
  bool WaitForEnd(absl::Duration timeout) const {
    for (const absl::Time until = absl::Now() + timeout;
         !ended_ && absl::Now() < until;) {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return ended_;
  }
  absl::Status end_status() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return end_status_;
  }

 private:
  mutable std::mutex mutex_;
  std::shared_ptr<const pb::Weights> weights_;
  absl::Status end_status_;
  std::atomic<bool> ended_{false};
};

class Session {
 public:
  Session(const RemoteActorConfig& config,
          std::shared_ptr<grpc::Channel> channel, ActorMetrics* metrics,
          PhaseTimes& times, RoundWatchdog& watchdog)
      : config_(config),
        stub_(pb::Learner::NewStub(channel)),
        metrics_(metrics),
        times_(times),
        watchdog_(watchdog) {}

  // Registers, then acts and streams until an error or `stop`.
  // `progressed` tells whether the learner accepted us at all.
  absl::Status Run(const EnvSpec& spec, std::unique_ptr<ActorCore>& actor,
                   const std::atomic<bool>& stop, bool& progressed) {
    pb::RegisterResponse response;
    if (absl::Status status = Register(spec, response); !status.ok()) {
      return status;
    }
    progressed = true;
    const pb::DistributedSettings& distributed =
        response.run_config().distributed();
    watchdog_.SetTimeout(
        distributed.has_actor_stall_timeout_s()
            ? absl::Seconds(distributed.actor_stall_timeout_s())
            : absl::ZeroDuration());
    if (actor == nullptr) {
      absl::StatusOr<std::unique_ptr<ActorCore>> created =
          CreateActor(response);
      if (!created.ok()) return created.status();
      actor = *std::move(created);
    }
    actor->set_stream_actor_id(response.actor_id());
    if (absl::Status status = Apply(response.weights(), *actor); !status.ok()) {
      return status;
    }
    std::fprintf(stderr,
                 "%s: registered as actor %ld, policy version %ld, env seed "
                 "%llu\n",
                 config_.name.c_str(), static_cast<long>(response.actor_id()),
                 static_cast<long>(actor->policy_version()),
                 static_cast<unsigned long long>(actor->env_seed()));
    return Stream(response, *actor, stop);
  }

 private:
  absl::Status Register(const EnvSpec& spec, pb::RegisterResponse& response) {
    pb::RegisterRequest request;
    EnvSpecToProto(spec, request.mutable_spec());
    request.set_actor_name(config_.name);
    request.set_num_envs(config_.num_envs);
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() +
                         std::chrono::seconds(120));
    AddAuthToken(config_.security, context);
    return FromGrpc(stub_->Register(&context, request, &response),
                    "registration");
  }

  // The actor the learner's run config describes (the first registration's;
  // later ones keep it and its environments).
  absl::StatusOr<std::unique_ptr<ActorCore>> CreateActor(
      const pb::RegisterResponse& response) const {
    const pb::RunConfig& run = response.run_config();
    // The learner's run config says how it wraps the environment, cuts
    // segments and acts; the registration carried the environment's own
    // spec, and this actor's env streams are its own.
    absl::StatusOr<ActorConfig> actor_config = ActorConfigOf(run);
    if (!actor_config.ok()) {
      return absl::InvalidArgumentError(absl::StrCat(
          "the learner's run config: ", actor_config.status().message()));
    }
    actor_config->env = config_.env;
    // An actor started without --env_kwargs (by Slurm or a Deployment)
    // makes its Python envs as the run does.
    if (!config_.env_kwargs.empty()) {
      actor_config->env_options.python_kwargs = config_.env_kwargs;
    }
    actor_config->num_envs = config_.num_envs;
    actor_config->seed =
        config_.seed.has_value()
            ? *config_.seed
            : ActorEnvSeed(run.training().seed(), response.actor_id());
    actor_config->actor_id = response.actor_id();
    return ActorCore::Create(*actor_config);
  }

  // The session's weights subscription and segment stream around Act.
  absl::Status Stream(const pb::RegisterResponse& response, ActorCore& actor,
                      const std::atomic<bool>& stop) {
    // Empty until the subscription's first message: the weights and grant
    // in force once this actor is in the learner's pool (its calls are
    // open), so that it never acts for a sync batch completed without it.
    WeightsSlot slot;
    grpc::ClientContext subscription_context;
    AddAuthToken(config_.security, subscription_context);
    subscription_context.AddMetadata(kSessionMetadataKey, response.session());
    pb::WeightsRequest weights_request;
    weights_request.set_actor_id(response.actor_id());
    weights_request.set_known_version(actor.policy_version());
    std::unique_ptr<grpc::ClientReader<pb::Weights>> subscription =
        stub_->SubscribeWeights(&subscription_context, weights_request);
    std::thread reader([&] {
      pb::Weights weights;
      while (subscription->Read(&weights)) slot.Put(weights);
      slot.End(FromGrpc(subscription->Finish(), "weights subscription"));
    });

    grpc::ClientContext stream_context;
    AddAuthToken(config_.security, stream_context);
    stream_context.AddMetadata(kSessionMetadataKey, response.session());
    pb::SegmentAck ack;
    std::unique_ptr<grpc::ClientWriter<pb::Segment>> writer =
        stub_->StreamSegments(&stream_context, &ack);
    StreamSink sink(*writer, metrics_, times_, watchdog_);
    const absl::Status status =
        Act(response.run_config(), actor, slot, sink, stop);
    writer->WritesDone();
    const absl::Status finished = FromGrpc(writer->Finish(), "segment stream");
    // A learner that completes the run says so on the subscription and then
    // shuts down, which can cut the segment stream before that word has
    // been read: it gets a moment to arrive before the subscription is
    // cancelled (a learner that is gone ends the subscription at once).
    if (!stop &&
        (absl::IsUnavailable(status) || absl::IsUnavailable(finished))) {
      slot.WaitForEnd(kRunOverGrace);
    }
    subscription_context.TryCancel();
    reader.join();
    if (stop) return absl::OkStatus();
    // The run's end outranks the segment stream's, cut by the shutdown.
    if (absl::IsOutOfRange(status)) return status;
    if (slot.ended() && absl::IsOutOfRange(slot.end_status())) {
      return slot.end_status();
    }
    return finished.ok() ? status : finished;
  }

  // Acts and sends until an error, the subscription's end or `stop` (OK).
  // Pacing (HorizonPacer): each horizon begins only within the learner's
  // grant of horizons per version, with the newest weights; the first waits
  // for the subscription's first message. A sync actor (lead 0) acts exactly
  // its grant with each version, all on-policy; an asynchronous one may lead by
  // up to two versions (no more than the allowed policy lag), acting during the
  // learner's updates, which is how acting hides behind learning, and never so
  // far ahead that its segments would grow stale or memory would grow.
  absl::Status Act(const pb::RunConfig& run, ActorCore& actor,
                   const WeightsSlot& slot, SegmentSink& sink,
                   const std::atomic<bool>& stop) {
    const int64_t rounds_per_horizon = std::max<int64_t>(
        1, run.training().horizon() / run.training().segment_length());
    HorizonPacer pacer(
        run.distributed().sync()
            ? 0
            : std::min<int64_t>(2, run.distributed().max_policy_lag()));
    for (int64_t rounds = 0; !stop; ++rounds) {
      absl::Status ready = rounds % rounds_per_horizon == 0
                               ? AwaitGrant(pacer, actor, slot, stop)
                               : ApplyNewest(actor, slot);
      if (!ready.ok()) return ready;
      if (stop) break;
      if (rounds % rounds_per_horizon == 0) {
        pacer.Add(actor.policy_version(), 1);
      }
      if (absl::Status status = CollectRound(actor, sink); !status.ok()) {
        return status;
      }
    }
    return absl::OkStatus();
  }

  // Waits until a horizon may begin with the newest weights (applied);
  // the subscription's end is an error (Unavailable if it ended cleanly).
  absl::Status AwaitGrant(const HorizonPacer& pacer, ActorCore& actor,
                          const WeightsSlot& slot,
                          const std::atomic<bool>& stop) {
    while (!stop) {
      if (absl::Status status = ApplyNewest(actor, slot); !status.ok()) {
        return status;
      }
      std::shared_ptr<const pb::Weights> newest = slot.Get();
      if (newest != nullptr && newest->version() == actor.policy_version() &&
          pacer.Credit(newest->version(), GrantedHorizons(*newest)) > 0) {
        return absl::OkStatus();
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    return absl::OkStatus();
  }

  // The subscription's newest weights, if newer than the actor's.
  absl::Status ApplyNewest(ActorCore& actor, const WeightsSlot& slot) {
    if (std::shared_ptr<const pb::Weights> newest = slot.Get();
        newest != nullptr && newest->version() > actor.policy_version()) {
      if (absl::Status status = Apply(*newest, actor); !status.ok()) {
        return status;
      }
    }
    if (!slot.ended()) return absl::OkStatus();
    const absl::Status status = slot.end_status();
    return status.ok()
               ? absl::UnavailableError("the weights subscription ended")
               : status;
  }

  // One segment from every env, timed and counted.
  absl::Status CollectRound(ActorCore& actor, SegmentSink& sink) {
    const double inference_before = actor.inference_seconds();
    const double env_before = actor.env_seconds();
    watchdog_.Busy();
    const absl::Status status = actor.CollectSegments(sink);
    watchdog_.Idle();
    const double inference = actor.inference_seconds() - inference_before;
    const double physics = actor.env_seconds() - env_before;
    times_.Add(kInferencePhase, inference);
    times_.Add(kPhysicsPhase, physics);
    if (metrics_ != nullptr) {
      metrics_->RecordEnvSteps(actor.env_steps());
      metrics_->AddInferenceSeconds(inference);
      metrics_->AddEnvSeconds(physics);
      metrics_->SetPolicyVersion(actor.policy_version());
    }
    return status;
  }

  static absl::Status Apply(const pb::Weights& proto, ActorCore& actor) {
    absl::StatusOr<PolicyWeights> weights = WeightsFromProto(proto, 1LL << 30);
    if (!weights.ok()) return weights.status();
    return actor.SetWeights(*weights);
  }

  const RemoteActorConfig& config_;
  std::unique_ptr<pb::Learner::Stub> stub_;
  ActorMetrics* metrics_;
  PhaseTimes& times_;
  RoundWatchdog& watchdog_;
};

// Prints the actor's time split when it stops, however it stops.
class TimeSplitReport {
 public:
  explicit TimeSplitReport(const std::string& name)
      : name_(name), times_({"inference", "physics", "send"}) {}
  ~TimeSplitReport() {
    std::fprintf(stderr, "%s: %s\n", name_.c_str(),
                 times_.Summary("waiting").c_str());
  }
  PhaseTimes& times() { return times_; }

 private:
  std::string name_;
  PhaseTimes times_;
};

// The environment's own spec (unwrapped: the learner's run config says
// how to wrap it), which the registration carries.
absl::StatusOr<EnvSpec> ProbeEnvSpec(const RemoteActorConfig& config) {
  EnvOptions own;
  own.python_kwargs = config.env_kwargs;
  absl::StatusOr<std::unique_ptr<Environment>> probe =
      MakeEnvironment(config.env, own);
  if (!probe.ok()) return probe.status();
  const EnvSpec spec = (*probe)->spec();
  probe->reset();
  return spec;
}

grpc::ChannelArguments ChannelArgumentsFor(const RemoteActorConfig& config) {
  grpc::ChannelArguments arguments;
  arguments.SetMaxReceiveMessageSize(config.max_message_bytes);
  arguments.SetMaxSendMessageSize(config.max_message_bytes);
  // A dead link is noticed by pings, not by TCP's backoff (keepalive.h).
  arguments.SetInt(GRPC_ARG_KEEPALIVE_TIME_MS, kKeepaliveIntervalMs);
  arguments.SetInt(GRPC_ARG_KEEPALIVE_TIMEOUT_MS, kKeepaliveTimeoutMs);
  // Pings while the actor waits for weights and sends nothing.
  arguments.SetInt(GRPC_ARG_HTTP2_MAX_PINGS_WITHOUT_DATA, 0);
  arguments.SetInt(GRPC_ARG_MAX_RECONNECT_BACKOFF_MS, kMaxReconnectBackoffMs);
  return arguments;
}

// Null when the config asks for no metrics.
absl::StatusOr<std::unique_ptr<ActorMetrics>> StartMetrics(
    const RemoteActorConfig& config) {
  if (config.metrics_address.empty()) return nullptr;
  absl::StatusOr<std::unique_ptr<ActorMetrics>> started =
      ActorMetrics::Start(config.metrics_address, config.security.auth_token);
  if (!started.ok()) return started.status();
  std::unique_ptr<ActorMetrics> metrics = *std::move(started);
  std::fprintf(stderr, "%s: metrics on port %d\n", config.name.c_str(),
               metrics->port());
  if (!config.metrics_port_file.empty()) {
    if (absl::Status status =
            WritePortFile(config.metrics_port_file, metrics->port());
        !status.ok()) {
      return status;
    }
  }
  return metrics;
}

// Short naps, so that a stop request ends the wait at once.
void SleepUnlessStopped(absl::Duration duration,
                        const std::atomic<bool>& stop) {
  for (absl::Time until = absl::Now() + duration;
       !stop && absl::Now() < until;) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

}  // namespace

uint64_t ActorEnvSeed(uint64_t run_seed, int64_t actor_id) {
  return SplitMixSeed(run_seed, static_cast<uint64_t>(actor_id));
}

absl::Status RunRemoteActor(const RemoteActorConfig& config,
                            const std::atomic<bool>& stop) {
  absl::StatusOr<EnvSpec> spec = ProbeEnvSpec(config);
  if (!spec.ok()) return spec.status();
  const grpc::ChannelArguments arguments = ChannelArgumentsFor(config);
  absl::StatusOr<std::shared_ptr<grpc::ChannelCredentials>> credentials =
      MakeChannelCredentials(config.security);
  if (!credentials.ok()) return credentials.status();
  absl::StatusOr<std::unique_ptr<ActorMetrics>> started = StartMetrics(config);
  if (!started.ok()) return started.status();
  const std::unique_ptr<ActorMetrics> metrics = *std::move(started);
  TimeSplitReport report(config.name);
  RoundWatchdog watchdog(config.name, config.env);
  std::unique_ptr<ActorCore> actor;  // kept across reconnects
  int failures = 0;
  absl::Duration backoff = config.initial_backoff;
  while (!stop) {
    const std::shared_ptr<grpc::Channel> channel =
        grpc::CreateCustomChannel(config.learner, *credentials, arguments);
    Session session(config, channel, metrics.get(), report.times(), watchdog);
    bool progressed = false;
    const absl::Status status = session.Run(*spec, actor, stop, progressed);
    if (stop) break;
    if (absl::IsOutOfRange(status)) {
      // The learner completed the run (registration or subscription).
      std::fprintf(stderr, "%s: %s; exiting\n", config.name.c_str(),
                   std::string(status.message()).c_str());
      break;
    }
    if (IsRefusal(status)) return status;
    if (progressed) {
      failures = 0;
      backoff = config.initial_backoff;
    }
    if (config.max_reconnects >= 0 && failures >= config.max_reconnects) {
      return absl::UnavailableError(absl::StrCat(
          "giving up after ", failures, " reconnects: ", status.message()));
    }
    ++failures;
    if (metrics != nullptr) metrics->AddReconnect();
    std::fprintf(stderr, "%s: %s; reconnecting to %s in %s\n",
                 config.name.c_str(), std::string(status.message()).c_str(),
                 config.learner.c_str(), absl::FormatDuration(backoff).c_str());
    SleepUnlessStopped(backoff, stop);
    backoff = std::min(backoff * 2, config.max_backoff);
  }
  return absl::OkStatus();
}

}  // namespace vantage
