#ifndef VANTAGE_LEARNER_SERVICE_LEARNER_SERVICE_H_
#define VANTAGE_LEARNER_SERVICE_LEARNER_SERVICE_H_

#include <grpcpp/grpcpp.h>

#include <memory>
#include <string>

#include "absl/status/statusor.h"
#include "learner/service/actor_gateway.h"
#include "learner/service/security.h"
#include "proto/vantage.grpc.pb.h"

namespace vantage {

// absl::Status -> grpc::Status with the same code and message.
grpc::Status ToGrpcStatus(const absl::Status& status);

// The gRPC face of an ActorGateway; every method only translates, after
// checking the auth token (if one is required).
class LearnerService final : public pb::Learner::Service {
 public:
  explicit LearnerService(ActorGateway& gateway) : gateway_(gateway) {}

  // Every call must then carry `authorization: Bearer <token>`; empty: none.
  // Set before the server starts.
  void RequireAuthToken(std::string token) { auth_token_ = std::move(token); }

  grpc::Status Register(grpc::ServerContext* context,
                        const pb::RegisterRequest* request,
                        pb::RegisterResponse* response) override;
  // Ends at the first refused segment with its error (counted); the actor
  // reopens the stream. Too stale segments are dropped and counted in the
  // ack's `rejected`.
  grpc::Status StreamSegments(grpc::ServerContext* context,
                              grpc::ServerReader<pb::Segment>* reader,
                              pb::SegmentAck* ack) override;
  grpc::Status SubscribeWeights(
      grpc::ServerContext* context, const pb::WeightsRequest* request,
      grpc::ServerWriter<pb::Weights>* writer) override;
  grpc::Status GetWeights(grpc::ServerContext* context,
                          const pb::WeightsRequest* request,
                          pb::Weights* response) override;

 private:
  ActorGateway& gateway_;
  std::string auth_token_;
};

struct ServerOptions {
  std::string listen = "127.0.0.1:0";  // port 0: the OS picks one
  int max_message_bytes = 256 << 20;
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
