#include "learner/service/learner_service.h"

#include <grpcpp/health_check_service_interface.h>
#include <grpcpp/support/proto_buffer_reader.h>

#include <algorithm>
#include <exception>
#include <limits>
#include <new>
#include <string>
#include <vector>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "common/net/keepalive.h"
#include "proto/wire_format.h"

namespace vantage {
namespace {

// How often a waiting subscription checks for cancellation.
constexpr absl::Duration kPoll = absl::Milliseconds(200);
// How long a registration may wait for the learner's first weights.
constexpr absl::Duration kRegistrationWait = absl::Seconds(60);
// StreamSegments' index in the service definition (proto/vantage.proto).
constexpr int kStreamSegmentsMethod = 1;

// Runs a handler body; an exception (an allocation that failed, a LibTorch
// error nobody foresaw) becomes an error reply and a count instead of
// leaving the server with gRPC's bare UNKNOWN.
template <typename Body>
grpc::Status Guarded(ActorGateway& gateway, Body body) {
  try {
    return body();
  } catch (const std::bad_alloc&) {
    gateway.CountRejected("out_of_memory");
    return grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED,
                        "the learner could not allocate memory for this call");
  } catch (const std::exception& e) {
    gateway.CountRejected("internal_error");
    return grpc::Status(grpc::StatusCode::INTERNAL,
                        absl::StrCat("learner error: ", e.what()));
  }
}

// Reads the one request of a streamed handler (after the token check) and
// refuses one larger than `limit` bytes.
template <typename Request, typename Streamer>
grpc::Status ReadRequest(Streamer& streamer, int64_t limit, const char* what,
                         Request& request) {
  if (!streamer.Read(&request)) {
    return grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                        absl::StrCat("no readable ", what));
  }
  const size_t bytes = request.ByteSizeLong();
  if (static_cast<int64_t>(bytes) > limit) {
    return grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                        absl::StrCat(what, " of ", bytes,
                                     " bytes exceeds the limit of ", limit));
  }
  return grpc::Status::OK;
}

absl::string_view SessionOf(const grpc::ServerContext& context) {
  const auto& metadata = context.client_metadata();
  auto it = metadata.find(kSessionMetadataKey);
  if (it == metadata.end()) return absl::string_view();
  return absl::string_view(it->second.data(), it->second.size());
}

}  // namespace

std::string PeerHost(absl::string_view peer) {
  if (!absl::StartsWith(peer, "ipv4:") && !absl::StartsWith(peer, "ipv6:")) {
    return std::string(peer);
  }
  const size_t port = peer.rfind(':');
  return std::string(peer.substr(0, port));
}

grpc::Status ToGrpcStatus(const absl::Status& status) {
  if (status.ok()) return grpc::Status::OK;
  return grpc::Status(static_cast<grpc::StatusCode>(status.code()),
                      std::string(status.message()));
}

LearnerService::LearnerService(ActorGateway& gateway, ServiceLimits limits)
    : gateway_(gateway), limits_(limits) {
  // Raw bytes instead of pb::Segment: gRPC's own decoding ends a stream
  // whose bytes do not parse as if the client had finished it.
  MarkMethodStreamed(
      kStreamSegmentsMethod,
      new grpc::internal::ClientStreamingHandler<
          LearnerService, grpc::ByteBuffer, pb::SegmentAck>(
          [](LearnerService* service, grpc::ServerContext* context,
             grpc::ServerReader<grpc::ByteBuffer>* reader,
             pb::SegmentAck* ack) {
            return service->SegmentStream(context, reader, ack);
          },
          this));
}

grpc::Status LearnerService::StreamedRegister(
    grpc::ServerContext* context,
    grpc::ServerUnaryStreamer<pb::RegisterRequest, pb::RegisterResponse>*
        streamer) {
  if (grpc::Status auth = CheckAuthToken(*context, auth_token_); !auth.ok()) {
    return auth;
  }
  return Guarded(gateway_, [&] {
    pb::RegisterRequest request;
    if (grpc::Status read = ReadRequest(*streamer, limits_.max_request_bytes,
                                        "RegisterRequest", request);
        !read.ok()) {
      return read;
    }
    absl::StatusOr<pb::RegisterResponse> registered = gateway_.Register(
        request, PeerHost(context->peer()), kRegistrationWait);
    if (!registered.ok()) return ToGrpcStatus(registered.status());
    streamer->Write(*registered);
    return grpc::Status::OK;
  });
}

absl::StatusOr<int64_t> LearnerService::OpenBoundCall(
    grpc::ServerContext& context, CallKind kind, int64_t& actor_id) {
  absl::StatusOr<int64_t> attached = gateway_.Attach(SessionOf(context));
  if (!attached.ok()) return attached.status();
  actor_id = *attached;
  std::lock_guard<std::mutex> lock(calls_mutex_);
  // One call of each kind per actor: an actor that reconnects leaves its
  // old call behind, and a client that opens many holds only one thread.
  for (auto& [key, call] : calls_) {
    if (call.actor_id == actor_id && call.kind == kind) {
      call.context->TryCancel();
    }
  }
  const int64_t key = next_call_key_++;
  calls_[key] = {&context, kind, actor_id, absl::Now()};
  return key;
}

void LearnerService::Touch(int64_t key) {
  std::lock_guard<std::mutex> lock(calls_mutex_);
  auto it = calls_.find(key);
  if (it != calls_.end()) it->second.last_activity = absl::Now();
}

void LearnerService::CloseBoundCall(int64_t key, int64_t actor_id) {
  {
    std::lock_guard<std::mutex> lock(calls_mutex_);
    calls_.erase(key);
  }
  gateway_.Detach(actor_id);
}

int LearnerService::CancelIdleStreams(absl::Time now) {
  int cancelled = 0;
  std::lock_guard<std::mutex> lock(calls_mutex_);
  for (auto& [key, call] : calls_) {
    if (call.kind == CallKind::kSegments &&
        now - call.last_activity > limits_.idle_stream_timeout) {
      call.context->TryCancel();
      // Counted once: the entry's clock restarts until its handler ends.
      call.last_activity = now;
      gateway_.CountRejected("idle_stream");
      ++cancelled;
    }
  }
  return cancelled;
}

int64_t LearnerService::open_streams() const {
  std::lock_guard<std::mutex> lock(calls_mutex_);
  return static_cast<int64_t>(calls_.size());
}

grpc::Status LearnerService::SegmentStream(
    grpc::ServerContext* context, grpc::ServerReader<grpc::ByteBuffer>* reader,
    pb::SegmentAck* ack) {
  if (grpc::Status auth = CheckAuthToken(*context, auth_token_); !auth.ok()) {
    return auth;
  }
  int64_t actor_id = -1;
  absl::StatusOr<int64_t> key =
      OpenBoundCall(*context, CallKind::kSegments, actor_id);
  if (!key.ok()) return ToGrpcStatus(key.status());
  const grpc::Status status = Guarded(gateway_, [&] {
    grpc::ByteBuffer bytes;
    pb::Segment segment;
    std::string dropped;
    while (reader->Read(&bytes)) {
      Touch(*key);
      if (static_cast<int64_t>(bytes.Length()) >
          limits_.max_segment_message_bytes) {
        gateway_.CountRejected("oversized");
        return grpc::Status(
            grpc::StatusCode::INVALID_ARGUMENT,
            absl::StrCat("a segment message of ", bytes.Length(),
                         " bytes exceeds this run's limit of ",
                         limits_.max_segment_message_bytes));
      }
      grpc::ProtoBufferReader input(&bytes);
      if (!segment.ParseFromZeroCopyStream(&input)) {
        gateway_.CountRejected("unparsable");
        return grpc::Status(
            grpc::StatusCode::INVALID_ARGUMENT,
            absl::StrCat("message ", ack->accepted() + ack->rejected(),
                         " of the stream is not a Segment"));
      }
      if (absl::Status admitted = gateway_.Admit(actor_id, segment, &dropped);
          !admitted.ok()) {
        return ToGrpcStatus(admitted);
      }
      if (dropped.empty()) {
        ack->set_accepted(ack->accepted() + 1);
      } else {
        ack->set_rejected(ack->rejected() + 1);
        ack->set_last_error(dropped);
      }
    }
    if (context->IsCancelled()) {
      return grpc::Status(grpc::StatusCode::CANCELLED,
                          "the learner ended this stream (idle, or the same "
                          "actor opened a newer one)");
    }
    return grpc::Status::OK;
  });
  CloseBoundCall(*key, actor_id);
  return status;
}

grpc::Status LearnerService::StreamedSubscribeWeights(
    grpc::ServerContext* context,
    grpc::ServerSplitStreamer<pb::WeightsRequest, pb::Weights>* streamer) {
  if (grpc::Status auth = CheckAuthToken(*context, auth_token_); !auth.ok()) {
    return auth;
  }
  int64_t actor_id = -1;
  absl::StatusOr<int64_t> key =
      OpenBoundCall(*context, CallKind::kWeights, actor_id);
  if (!key.ok()) return ToGrpcStatus(key.status());
  const grpc::Status status = Guarded(gateway_, [&] {
    pb::WeightsRequest request;
    if (grpc::Status read = ReadRequest(*streamer, limits_.max_request_bytes,
                                        "WeightsRequest", request);
        !read.ok()) {
      return read;
    }
    // The weights in force first (with the grant in force, which the
    // actor's registration may predate), then every version and grant.
    int64_t seen = -1;
    while (!context->IsCancelled() && !gateway_.closed()) {
      std::shared_ptr<const pb::Weights> weights =
          gateway_.WaitForWeightsAfter(&seen, kPoll);
      if (weights == nullptr) continue;
      if (!streamer->Write(*weights)) break;
      Touch(*key);
    }
    if (gateway_.run_over()) {
      return grpc::Status(grpc::StatusCode::OUT_OF_RANGE, kRunOver);
    }
    return grpc::Status::OK;
  });
  CloseBoundCall(*key, actor_id);
  return status;
}

grpc::Status LearnerService::StreamedGetWeights(
    grpc::ServerContext* context,
    grpc::ServerUnaryStreamer<pb::WeightsRequest, pb::Weights>* streamer) {
  if (grpc::Status auth = CheckAuthToken(*context, auth_token_); !auth.ok()) {
    return auth;
  }
  return Guarded(gateway_, [&] {
    pb::WeightsRequest request;
    if (grpc::Status read = ReadRequest(*streamer, limits_.max_request_bytes,
                                        "WeightsRequest", request);
        !read.ok()) {
      return read;
    }
    std::shared_ptr<const pb::Weights> weights =
        gateway_.WaitForWeightsNewerThan(-1, absl::ZeroDuration());
    if (weights == nullptr) {
      return grpc::Status(grpc::StatusCode::UNAVAILABLE,
                          "the learner has published no weights yet");
    }
    streamer->Write(*weights);
    return grpc::Status::OK;
  });
}

absl::StatusOr<RunningServer> StartServer(const ServerOptions& options,
                                          LearnerService& service) {
  absl::StatusOr<std::shared_ptr<grpc::ServerCredentials>> credentials =
      MakeServerCredentials(options.security);
  if (!credentials.ok()) return credentials.status();
  service.RequireAuthToken(options.security.auth_token);
  // grpc.health.v1.Health, for orchestrators' probes (Kubernetes' gRPC
  // probes, `vantage health`): it answers without the auth token, which a
  // probe cannot carry, and tells only whether the server is up.
  grpc::EnableDefaultHealthCheckService(true);
  RunningServer running;
  grpc::ServerBuilder builder;
  builder.AddListeningPort(options.listen, *credentials, &running.port);
  builder.SetMaxReceiveMessageSize(static_cast<int>(std::min<int64_t>(
      options.max_receive_message_bytes, std::numeric_limits<int>::max())));
  builder.SetMaxSendMessageSize(static_cast<int>(std::min<int64_t>(
      options.max_send_message_bytes, std::numeric_limits<int>::max())));
  // Past max_threads, new calls are refused with RESOURCE_EXHAUSTED
  // instead of a thread each; the memory quota bounds gRPC's buffers.
  grpc::ResourceQuota quota("vantage-learner");
  quota.SetMaxThreads(options.max_threads);
  quota.Resize(static_cast<size_t>(options.max_memory_bytes));
  builder.SetResourceQuota(quota);
  // An actor keeps three calls open on one connection.
  builder.AddChannelArgument(GRPC_ARG_MAX_CONCURRENT_STREAMS, 16);
  // Actors ping every kKeepaliveIntervalMs to notice a dead link
  // (common/net/keepalive.h); by default gRPC would close their
  // connections for it.
  builder.AddChannelArgument(
      GRPC_ARG_HTTP2_MIN_RECV_PING_INTERVAL_WITHOUT_DATA_MS,
      kMinPingIntervalMs);
  builder.AddChannelArgument(GRPC_ARG_KEEPALIVE_PERMIT_WITHOUT_CALLS, 1);
  builder.RegisterService(&service);
  running.server = builder.BuildAndStart();
  if (running.server == nullptr || running.port == 0) {
    return absl::UnavailableError(
        absl::StrCat("cannot listen on ", options.listen));
  }
  return running;
}

}  // namespace vantage
