#include "learner/service/learner_service.h"

#include <string>

#include "absl/strings/str_cat.h"

namespace vantage {
namespace {

// How often a waiting subscription checks for cancellation.
constexpr absl::Duration kPoll = absl::Milliseconds(200);
// How long a registration may wait for the learner's first weights.
constexpr absl::Duration kRegistrationWait = absl::Seconds(60);

}  // namespace

grpc::Status ToGrpcStatus(const absl::Status& status) {
  if (status.ok()) return grpc::Status::OK;
  return grpc::Status(static_cast<grpc::StatusCode>(status.code()),
                      std::string(status.message()));
}

grpc::Status LearnerService::Register(grpc::ServerContext* context,
                                      const pb::RegisterRequest* request,
                                      pb::RegisterResponse* response) {
  if (grpc::Status auth = CheckAuthToken(*context, auth_token_); !auth.ok()) {
    return auth;
  }
  absl::StatusOr<pb::RegisterResponse> registered =
      gateway_.Register(*request, kRegistrationWait);
  if (!registered.ok()) return ToGrpcStatus(registered.status());
  *response = *std::move(registered);
  return grpc::Status::OK;
}

grpc::Status LearnerService::StreamSegments(
    grpc::ServerContext* context, grpc::ServerReader<pb::Segment>* reader,
    pb::SegmentAck* ack) {
  if (grpc::Status auth = CheckAuthToken(*context, auth_token_); !auth.ok()) {
    return auth;
  }
  pb::Segment segment;
  std::string dropped;
  while (reader->Read(&segment)) {
    if (absl::Status status = gateway_.Admit(segment, &dropped); !status.ok()) {
      return ToGrpcStatus(status);
    }
    if (dropped.empty()) {
      ack->set_accepted(ack->accepted() + 1);
    } else {
      ack->set_rejected(ack->rejected() + 1);
      ack->set_last_error(dropped);
    }
  }
  return grpc::Status::OK;
}

grpc::Status LearnerService::SubscribeWeights(
    grpc::ServerContext* context, const pb::WeightsRequest* request,
    grpc::ServerWriter<pb::Weights>* writer) {
  if (grpc::Status auth = CheckAuthToken(*context, auth_token_); !auth.ok()) {
    return auth;
  }
  int64_t known = request->known_version();
  while (!context->IsCancelled() && !gateway_.closed()) {
    std::shared_ptr<const pb::Weights> weights =
        gateway_.WaitForWeightsNewerThan(known, kPoll);
    if (weights == nullptr) continue;
    if (!writer->Write(*weights)) break;
    known = weights->version();
  }
  return grpc::Status::OK;
}

grpc::Status LearnerService::GetWeights(grpc::ServerContext* context,
                                        const pb::WeightsRequest* request,
                                        pb::Weights* response) {
  if (grpc::Status auth = CheckAuthToken(*context, auth_token_); !auth.ok()) {
    return auth;
  }
  std::shared_ptr<const pb::Weights> weights =
      gateway_.WaitForWeightsNewerThan(-1, absl::ZeroDuration());
  if (weights == nullptr) {
    return grpc::Status(grpc::StatusCode::UNAVAILABLE,
                        "the learner has published no weights yet");
  }
  *response = *weights;
  return grpc::Status::OK;
}

absl::StatusOr<RunningServer> StartServer(const ServerOptions& options,
                                          LearnerService& service) {
  absl::StatusOr<std::shared_ptr<grpc::ServerCredentials>> credentials =
      MakeServerCredentials(options.security);
  if (!credentials.ok()) return credentials.status();
  service.RequireAuthToken(options.security.auth_token);
  RunningServer running;
  grpc::ServerBuilder builder;
  builder.AddListeningPort(options.listen, *credentials, &running.port);
  builder.SetMaxReceiveMessageSize(options.max_message_bytes);
  builder.SetMaxSendMessageSize(options.max_message_bytes);
  builder.RegisterService(&service);
  running.server = builder.BuildAndStart();
  if (running.server == nullptr || running.port == 0) {
    return absl::UnavailableError(
        absl::StrCat("cannot listen on ", options.listen));
  }
  return running;
}

}  // namespace vantage
