#include <ATen/ATen.h>
#include <grpcpp/grpcpp.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"
#include "common/env/environment.h"
#include "common/net/grpc_security.h"
#include "common/nn/networks.h"
#include "common/nn/policy_weights.h"
#include "common/nn/running_mean_std.h"
#include "common/rollout/segment_queue.h"
#include "common/util/constant_time.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "learner/service/actor_gateway.h"
#include "learner/service/learner_service.h"
#include "proto/vantage.grpc.pb.h"
#include "proto/vantage.pb.h"
#include "proto/wire_format.h"
#include "tests/fakes/pendulum_spec.h"

namespace vantage {
namespace {

using ::testing::HasSubstr;

constexpr int64_t kObs = kPendulumObservationSize;
constexpr char kToken[] = "s3cret-token-0123456789";
// Guards every call so that a server that never answers fails the test
// instead of hanging it.
constexpr auto kRpcDeadline = std::chrono::seconds(30);

PolicyWeights MakeWeights(int64_t version) {
  NetworkConfig network;
  network.hidden = {8};
  PolicyNetwork policy(PendulumSpec(), network);
  RunningMeanStd normalizer(kObs);
  return ExportPolicyWeights(*policy, normalizer, version);
}

// A directory of its own per test process, removed at the end.
class TempDir {
 public:
  TempDir()
      : path_(absl::StrCat(std::filesystem::temp_directory_path().string(),
                           "/vantage-security-test-", ::getpid())) {
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code error;
    std::filesystem::remove_all(path_, error);
  }
  std::string Write(const std::string& name, const std::string& contents) {
    const std::string path = path_ + "/" + name;
    std::ofstream(path, std::ios::trunc) << contents;
    return path;
  }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

// A self-signed certificate for localhost / 127.0.0.1 and its key; the
// certificate is its own CA.
struct Certificate {
  std::string cert;
  std::string key;
};

Certificate MakeCertificate(const TempDir& dir, const std::string& name) {
  Certificate made{dir.path() + "/" + name + ".crt",
                   dir.path() + "/" + name + ".key"};
  const std::string command = absl::StrCat(
      "openssl req -x509 -newkey rsa:2048 -nodes -days 1 -subj /CN=localhost "
      "-addext subjectAltName=DNS:localhost,IP:127.0.0.1 -keyout ",
      made.key, " -out ", made.cert, " >/dev/null 2>&1");
  EXPECT_EQ(std::system(command.c_str()), 0) << command;
  return made;
}

class SecurityTest : public ::testing::Test {
 protected:
  ~SecurityTest() override {
    if (gateway_ != nullptr) gateway_->Close();
    if (queue_ != nullptr) queue_->Close();
    if (server_.server != nullptr) {
      server_.server->Shutdown(std::chrono::system_clock::now() +
                               std::chrono::seconds(5));
    }
  }

  // A real server on a loopback port with published weights.
  absl::Status Start(const SecurityOptions& security) {
    queue_ = std::make_unique<SegmentQueue>(16);
    GatewayConfig config;
    pb::TrainingSettings& training = *config.run_config.mutable_training();
    training.set_env("InvertedPendulum");
    training.set_horizon(16);
    training.set_segment_length(8);
    gateway_ = std::make_unique<ActorGateway>(config, *queue_);
    gateway_->Publish(MakeWeights(3));
    service_ = std::make_unique<LearnerService>(*gateway_);
    ServerOptions options;
    options.security = security;
    absl::StatusOr<RunningServer> running = StartServer(options, *service_);
    if (!running.ok()) return running.status();
    server_ = *std::move(running);
    return absl::OkStatus();
  }

  // GetWeights from a fresh channel dialled with `security`.
  grpc::Status GetWeights(const SecurityOptions& security,
                          pb::Weights* weights = nullptr) {
    absl::StatusOr<std::shared_ptr<grpc::ChannelCredentials>> credentials =
        MakeChannelCredentials(security);
    EXPECT_TRUE(credentials.ok()) << credentials.status();
    if (!credentials.ok()) return grpc::Status(grpc::StatusCode::INTERNAL, "");
    auto stub = pb::Learner::NewStub(grpc::CreateChannel(
        absl::StrCat("127.0.0.1:", server_.port), *credentials));
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + kRpcDeadline);
    AddAuthToken(security, context);
    pb::Weights response;
    grpc::Status status =
        stub->GetWeights(&context, pb::WeightsRequest(), &response);
    if (weights != nullptr) *weights = response;
    return status;
  }

  std::unique_ptr<SegmentQueue> queue_;
  std::unique_ptr<ActorGateway> gateway_;
  std::unique_ptr<LearnerService> service_;
  RunningServer server_;
};

SecurityOptions WithToken(const std::string& token) {
  SecurityOptions options;
  options.auth_token = token;
  return options;
}

TEST(ConstantTimeEqualsTest, ComparesContentsAndLengths) {
  EXPECT_TRUE(ConstantTimeEquals("abc", "abc"));
  EXPECT_TRUE(ConstantTimeEquals("", ""));
  EXPECT_FALSE(ConstantTimeEquals("abc", "abd"));
  EXPECT_FALSE(ConstantTimeEquals("abc", "ab"));
  EXPECT_FALSE(ConstantTimeEquals("ab", "abc"));
  EXPECT_FALSE(ConstantTimeEquals("", "a"));
  // A prefix padded with zero bytes is still a different token.
  EXPECT_FALSE(ConstantTimeEquals(std::string("ab\0", 3), "ab"));
}

TEST(ReadTokenFileTest, StripsTheTrailingNewline) {
  TempDir dir;
  absl::StatusOr<std::string> token =
      ReadTokenFile(dir.Write("token", "abc def\n"));
  ASSERT_TRUE(token.ok()) << token.status();
  EXPECT_EQ(*token, "abc def");
  token = ReadTokenFile(dir.Write("crlf", "xyz\r\n"));
  ASSERT_TRUE(token.ok()) << token.status();
  EXPECT_EQ(*token, "xyz");
}

TEST(ReadTokenFileTest, AMissingOrEmptyFileIsAnErrorNamingIt) {
  TempDir dir;
  const std::string missing = dir.path() + "/no-such-token";
  absl::StatusOr<std::string> token = ReadTokenFile(missing);
  ASSERT_FALSE(token.ok());
  EXPECT_THAT(token.status().message(), HasSubstr(missing));

  const std::string empty = dir.Write("empty", "\n");
  token = ReadTokenFile(empty);
  ASSERT_FALSE(token.ok());
  EXPECT_EQ(token.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(token.status().message(), HasSubstr(empty));
  EXPECT_THAT(token.status().message(), HasSubstr("empty"));
}

TEST_F(SecurityTest, EveryCallWithoutTheRightTokenIsUnauthenticated) {
  ASSERT_TRUE(Start(WithToken(kToken)).ok());
  const std::string same_length(sizeof(kToken) - 1, 'x');
  for (const std::string& token :
       {std::string(), same_length, std::string("short"),
        std::string(kToken) + "-longer"}) {
    const grpc::Status status = GetWeights(WithToken(token));
    EXPECT_EQ(status.error_code(), grpc::StatusCode::UNAUTHENTICATED)
        << "token '" << token << "'";
    EXPECT_EQ(status.error_message(), "missing or wrong auth token");
  }
  pb::Weights weights;
  const grpc::Status status = GetWeights(WithToken(kToken), &weights);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(weights.version(), 3);
}

TEST_F(SecurityTest, TheTokenMustComeAsABearerCredential) {
  ASSERT_TRUE(Start(WithToken(kToken)).ok());
  auto stub = pb::Learner::NewStub(
      grpc::CreateChannel(absl::StrCat("127.0.0.1:", server_.port),
                          grpc::InsecureChannelCredentials()));
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + kRpcDeadline);
  context.AddMetadata("authorization", kToken);
  pb::Weights weights;
  EXPECT_EQ(
      stub->GetWeights(&context, pb::WeightsRequest(), &weights).error_code(),
      grpc::StatusCode::UNAUTHENTICATED);
}

TEST_F(SecurityTest, StreamingCallsAndRegistrationCheckTheTokenToo) {
  ASSERT_TRUE(Start(WithToken(kToken)).ok());
  auto stub = pb::Learner::NewStub(
      grpc::CreateChannel(absl::StrCat("127.0.0.1:", server_.port),
                          grpc::InsecureChannelCredentials()));
  {
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + kRpcDeadline);
    pb::RegisterRequest request;
    EnvSpecToProto(PendulumSpec(), request.mutable_spec());
    request.set_num_envs(1);
    pb::RegisterResponse response;
    EXPECT_EQ(stub->Register(&context, request, &response).error_code(),
              grpc::StatusCode::UNAUTHENTICATED);
  }
  {
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + kRpcDeadline);
    pb::SegmentAck ack;
    auto writer = stub->StreamSegments(&context, &ack);
    writer->WritesDone();
    EXPECT_EQ(writer->Finish().error_code(), grpc::StatusCode::UNAUTHENTICATED);
    EXPECT_EQ(queue_->size(), 0u);
  }
  {
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + kRpcDeadline);
    auto reader = stub->SubscribeWeights(&context, pb::WeightsRequest());
    pb::Weights weights;
    EXPECT_FALSE(reader->Read(&weights));
    EXPECT_EQ(reader->Finish().error_code(), grpc::StatusCode::UNAUTHENTICATED);
  }
}

TEST_F(SecurityTest, TlsRoundTripWithToken) {
  TempDir dir;
  const Certificate server = MakeCertificate(dir, "server");
  SecurityOptions server_options = WithToken(kToken);
  server_options.tls_cert_file = server.cert;
  server_options.tls_key_file = server.key;
  ASSERT_TRUE(Start(server_options).ok());

  SecurityOptions client = WithToken(kToken);
  client.tls_ca_file = server.cert;
  pb::Weights weights;
  const grpc::Status status = GetWeights(client, &weights);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(weights.version(), 3);

  client.auth_token.clear();
  EXPECT_EQ(GetWeights(client).error_code(), grpc::StatusCode::UNAUTHENTICATED);
  // Plaintext against TLS never gets as far as the service.
  EXPECT_EQ(GetWeights(WithToken(kToken)).error_code(),
            grpc::StatusCode::UNAVAILABLE);
  // Nor does a client that trusts another CA.
  SecurityOptions other = WithToken(kToken);
  other.tls_ca_file = MakeCertificate(dir, "other").cert;
  EXPECT_EQ(GetWeights(other).error_code(), grpc::StatusCode::UNAVAILABLE);
}

TEST_F(SecurityTest, ALearnerWithACaRequiresClientCertificates) {
  TempDir dir;
  const Certificate server = MakeCertificate(dir, "server");
  SecurityOptions server_options = WithToken(kToken);
  server_options.tls_cert_file = server.cert;
  server_options.tls_key_file = server.key;
  server_options.tls_ca_file = server.cert;
  ASSERT_TRUE(Start(server_options).ok());

  SecurityOptions client = WithToken(kToken);
  client.tls_ca_file = server.cert;
  EXPECT_FALSE(GetWeights(client).ok());
  client.tls_cert_file = server.cert;
  client.tls_key_file = server.key;
  const grpc::Status status = GetWeights(client);
  EXPECT_TRUE(status.ok()) << status.error_message();
}

TEST_F(SecurityTest, IncompleteOrUnreadableTlsSettingsAreErrors) {
  TempDir dir;
  SecurityOptions cert_only;
  cert_only.tls_cert_file = dir.Write("cert.pem", "x");
  absl::Status status = Start(cert_only);
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(status.message(), HasSubstr("--tls_key"));

  SecurityOptions ca_only;
  ca_only.tls_ca_file = dir.Write("ca.pem", "x");
  EXPECT_EQ(Start(ca_only).code(), absl::StatusCode::kInvalidArgument);

  SecurityOptions missing;
  missing.tls_cert_file = dir.path() + "/missing.crt";
  missing.tls_key_file = dir.Write("key.pem", "x");
  status = Start(missing);
  EXPECT_FALSE(status.ok());
  EXPECT_THAT(status.message(), HasSubstr(missing.tls_cert_file));

  SecurityOptions client_key_only;
  client_key_only.tls_key_file = dir.path() + "/key.pem";
  EXPECT_EQ(MakeChannelCredentials(client_key_only).status().code(),
            absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace vantage
