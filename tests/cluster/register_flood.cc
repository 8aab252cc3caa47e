// A client that holds valid credentials and floods a learner with
// registrations it never uses (no stream, no subscription), from one host,
// for a number of seconds; prints how many were granted and refused by
// code. The cluster test runs it on one host while actors on the others
// must still register at once.
//
//   register_flood LEARNER SECONDS ENV CERT KEY CA

#include <grpcpp/grpcpp.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <string>

#include "actor/envs/env_registry.h"
#include "common/net/grpc_security.h"
#include "proto/vantage.grpc.pb.h"
#include "proto/wire_format.h"

int main(int argc, char** argv) {
  if (argc != 7) {
    std::fprintf(stderr,
                 "usage: register_flood LEARNER SECONDS ENV CERT KEY CA\n");
    return 2;
  }
  vantage::SecurityOptions security;
  security.tls_cert_file = argv[4];
  security.tls_key_file = argv[5];
  security.tls_ca_file = argv[6];
  auto credentials = vantage::MakeChannelCredentials(security);
  auto env = vantage::MakeEnvironment(argv[3]);
  if (!credentials.ok() || !env.ok()) {
    std::fprintf(stderr, "register_flood: no credentials or env\n");
    return 2;
  }
  vantage::pb::RegisterRequest request;
  vantage::EnvSpecToProto((*env)->spec(), request.mutable_spec());
  request.set_actor_name("flood");
  request.set_num_envs(1);
  auto stub =
      vantage::pb::Learner::NewStub(grpc::CreateChannel(argv[1], *credentials));
  std::map<std::string, int> outcomes;
  std::map<std::string, std::string> first_message;
  const auto until = std::chrono::steady_clock::now() +
                     std::chrono::seconds(std::atoi(argv[2]));
  while (std::chrono::steady_clock::now() < until) {
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() +
                         std::chrono::seconds(5));
    vantage::pb::RegisterResponse response;
    const grpc::Status status = stub->Register(&context, request, &response);
    const std::string outcome =
        status.ok() ? "granted" : "code " + std::to_string(status.error_code());
    ++outcomes[outcome];
    first_message.emplace(outcome, status.error_message());
  }
  for (const auto& [outcome, count] : outcomes) {
    std::printf("register_flood: %s %d (%s)\n", outcome.c_str(), count,
                first_message[outcome].c_str());
  }
  return 0;
}
