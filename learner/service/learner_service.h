#ifndef VANTAGE_LEARNER_SERVICE_LEARNER_SERVICE_H_
#define VANTAGE_LEARNER_SERVICE_LEARNER_SERVICE_H_

#include <grpcpp/grpcpp.h>

#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <string>

#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "common/net/grpc_security.h"
#include "learner/service/actor_gateway.h"
#include "proto/vantage.grpc.pb.h"

namespace vantage {

// absl::Status -> grpc::Status with the same code and message.
grpc::Status ToGrpcStatus(const absl::Status& status);

// The host of a gRPC peer string ("ipv4:10.0.0.7:41234" -> "ipv4:10.0.0.7",
// "ipv6:[::1]:41234" -> "ipv6:[::1]"): what quotas per client count by, since
// each connection of a client has a port of its own. Other kinds (unix,
// inproc) are returned whole.
std::string PeerHost(absl::string_view peer);

// The gRPC face of an ActorGateway. Every method checks the auth token (if
// one is required) before it reads the request, and runs in its own
// server thread: the unary methods and SubscribeWeights use gRPC's streamed
// handlers, whose request is read only when the method asks for it, and
// StreamSegments reads raw bytes, so that bytes which are no segment are
// an INVALID_ARGUMENT reply instead of a silently ended stream. Errors the
// gateway does not foresee (an allocation failure) are replies too.
class LearnerService final : public pb::Learner::StreamedService {
 public:
  explicit LearnerService(ActorGateway& gateway,
                          ServiceLimits limits = ServiceLimits());

  // Every call must then carry `authorization: Bearer <token>`; empty: none.
  // Set before the server starts.
  void RequireAuthToken(std::string token) { auth_token_ = std::move(token); }

  grpc::Status StreamedRegister(
      grpc::ServerContext* context,
      grpc::ServerUnaryStreamer<pb::RegisterRequest, pb::RegisterResponse>*
          streamer) override;
  // Ends at the first refused segment with its error (counted); the actor
  // reopens the stream. Too stale and duplicate segments are dropped and
  // counted in the ack's `rejected`.
  grpc::Status SegmentStream(grpc::ServerContext* context,
                             grpc::ServerReader<grpc::ByteBuffer>* reader,
                             pb::SegmentAck* ack);
  grpc::Status StreamedSubscribeWeights(
      grpc::ServerContext* context,
      grpc::ServerSplitStreamer<pb::WeightsRequest, pb::Weights>* streamer)
      override;
  grpc::Status StreamedGetWeights(
      grpc::ServerContext* context,
      grpc::ServerUnaryStreamer<pb::WeightsRequest, pb::Weights>* streamer)
      override;

  // Cancels segment streams idle for longer than the limit. The learner
  // calls it periodically; returns how many it cancelled.
  int CancelIdleStreams(absl::Time now = absl::Now());
  // Open segment streams and weight subscriptions.
  int64_t open_streams() const;

 private:
  enum class CallKind { kSegments, kWeights };
  struct OpenCall {
    grpc::ServerContext* context;
    CallKind kind;
    int64_t actor_id;
    absl::Time last_activity;
  };

  // Attaches the call to its session's actor and ends the same actor's
  // older call of the same kind; returns the call's key for Touch/Close.
  absl::StatusOr<int64_t> OpenBoundCall(grpc::ServerContext& context,
                                        CallKind kind, int64_t& actor_id);
  void Touch(int64_t key);
  void CloseBoundCall(int64_t key, int64_t actor_id);

  ActorGateway& gateway_;
  const ServiceLimits limits_;
  std::string auth_token_;
  mutable std::mutex calls_mutex_;
  std::map<int64_t, OpenCall> calls_;
  int64_t next_call_key_ = 0;
};

struct ServerOptions {
  std::string listen = "127.0.0.1:0";  // port 0: the OS picks one
  // Largest message the server reads (a segment) and sends (weights).
  int64_t max_receive_message_bytes = 64 << 20;
  int64_t max_send_message_bytes = 256 << 20;
  // Server threads (each open call holds one) and memory gRPC may use.
  int max_threads = 600;
  int64_t max_memory_bytes = int64_t{1} << 30;
  SecurityOptions security;  // TLS and the auth token
};

struct RunningServer {
  std::unique_ptr<grpc::Server> server;
  int port = 0;
};

// Builds and starts a server for `service` (which must outlive it), with
// the credentials of options.security and its token required by `service`.
absl::StatusOr<RunningServer> StartServer(const ServerOptions& options,
                                          LearnerService& service);

}  // namespace vantage

#endif  // VANTAGE_LEARNER_SERVICE_LEARNER_SERVICE_H_
