#include "deploy/cli/health_command.h"

#include <grpcpp/grpcpp.h>

#include <chrono>
#include <cstdio>
#include <string>
#include <thread>

#include "absl/flags/flag.h"
#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "absl/time/clock.h"
#include "absl/time/time.h"
#include "common/net/grpc_security.h"
#include "deploy/cli/security_flags.h"
#include "deploy/cli/shared_flags.h"
#include "proto/health.grpc.pb.h"

ABSL_FLAG(double, timeout_s, 5,
          "how long to wait for the learner to answer SERVING (connecting "
          "included)");

namespace vantage {
namespace {

using HealthStatus = grpc::health::v1::HealthCheckResponse;

int Fail(int code, absl::string_view message) {
  return CommandFailure("health", code, std::string(message));
}

// Asks until SERVING or the deadline: a learner still loading its
// checkpoint is not up yet, and a probe that waits says so once.
int RunHealth(const std::vector<std::string>&) {
  const std::string learner = absl::GetFlag(FLAGS_learner);
  const double timeout_s = absl::GetFlag(FLAGS_timeout_s);
  if (learner.empty())
    return Fail(kUsageError, "--learner=HOST:PORT is required");
  if (!(timeout_s > 0)) return Fail(kUsageError, "--timeout_s must be > 0");
  absl::StatusOr<SecurityOptions> security =
      SecurityFromFlags(/*server=*/false);
  if (!security.ok()) return Fail(kUsageError, security.status().message());
  absl::StatusOr<std::shared_ptr<grpc::ChannelCredentials>> credentials =
      MakeChannelCredentials(*security);
  if (!credentials.ok())
    return Fail(kUsageError, credentials.status().message());
  const std::unique_ptr<grpc::health::v1::Health::Stub> stub =
      grpc::health::v1::Health::NewStub(
          grpc::CreateChannel(learner, *credentials));
  const absl::Time deadline = absl::Now() + absl::Seconds(timeout_s);
  std::string last = "no answer";
  while (true) {
    grpc::ClientContext context;
    context.set_deadline(absl::ToChronoTime(deadline));
    context.set_wait_for_ready(true);
    grpc::health::v1::HealthCheckRequest request;
    HealthStatus response;
    const grpc::Status status = stub->Check(&context, request, &response);
    if (status.ok()) {
      last = HealthStatus::ServingStatus_Name(response.status());
      if (response.status() == HealthStatus::SERVING) {
        std::printf("%s SERVING\n", learner.c_str());
        return 0;
      }
    } else if (status.error_code() != grpc::StatusCode::DEADLINE_EXCEEDED) {
      // gRPC's codes are absl's, number for number.
      last =
          absl::StrCat(absl::StatusCodeToString(
                           static_cast<absl::StatusCode>(status.error_code())),
                       ": ", status.error_message());
    }
    if (absl::Now() + absl::Milliseconds(200) >= deadline) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
  return Fail(kRuntimeError, absl::StrCat(learner, " is not SERVING after ",
                                          timeout_s, " s (", last, ")"));
}

}  // namespace

Command HealthCommand() {
  Command command;
  command.name = "health";
  command.summary = "ask a learner whether it serves (grpc.health.v1)";
  command.usage = "vantage health --learner=HOST:PORT [flags]";
  command.description =
      "Asks the learner's standard gRPC health service (grpc.health.v1,\n"
      "which answers without the auth token) until it says SERVING or\n"
      "--timeout_s pass: exit 0 and `HOST:PORT SERVING` on stdout, or exit\n"
      "1 with the last answer. For probes (Kubernetes' exec probes under\n"
      "TLS, Slurm scripts waiting for their learner); with TLS it takes the\n"
      "actor's --tls_* flags.";
  command.flags = {"learner", "timeout_s"};
  for (const std::string& name : SecurityFlagNames()) {
    if (name != "auth_token_file") command.flags.push_back(name);
  }
  command.example = "vantage health --learner=127.0.0.1:50051 --timeout_s=30";
  command.run = RunHealth;
  return command;
}

}  // namespace vantage
