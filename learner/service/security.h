#ifndef VANTAGE_LEARNER_SERVICE_SECURITY_H_
#define VANTAGE_LEARNER_SERVICE_SECURITY_H_

// Transport security and the shared auth token of the learner's gRPC
// service, for both ends: the learner serves with it, actors dial with it.

#include <grpcpp/grpcpp.h>

#include <memory>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "common/util/constant_time.h"

namespace vantage {

struct SecurityOptions {
  // Every RPC must carry `authorization: Bearer <auth_token>`; empty: none.
  std::string auth_token;
  // PEM files. Server: TLS needs cert and key; a CA then also requires
  // clients to present a certificate it signed. Client: any of them turns
  // TLS on; the CA verifies the server (empty: the system roots), cert and
  // key are the client's own certificate.
  std::string tls_cert_file;
  std::string tls_key_file;
  std::string tls_ca_file;

  bool tls() const {
    return !tls_cert_file.empty() || !tls_key_file.empty() ||
           !tls_ca_file.empty();
  }
};

// The token in `path` without its trailing newline; a missing, unreadable
// or empty file is an error naming it.
absl::StatusOr<std::string> ReadTokenFile(const std::string& path);

// Incomplete TLS settings are errors that name the missing flag.
absl::Status ValidateServerSecurity(const SecurityOptions& options);
absl::Status ValidateClientSecurity(const SecurityOptions& options);

// TLS or insecure credentials as `options` say; unreadable PEM files are
// errors naming them. The token is not part of them (see CheckAuthToken,
// AddAuthToken).
absl::StatusOr<std::shared_ptr<grpc::ServerCredentials>> MakeServerCredentials(
    const SecurityOptions& options);
absl::StatusOr<std::shared_ptr<grpc::ChannelCredentials>>
MakeChannelCredentials(const SecurityOptions& options);

// Adds the token (if any) to one call's metadata.
void AddAuthToken(const SecurityOptions& options, grpc::ClientContext& context);

// OK if `token` is empty or the call carries it; UNAUTHENTICATED otherwise.
grpc::Status CheckAuthToken(const grpc::ServerContext& context,
                            absl::string_view token);

}  // namespace vantage

#endif  // VANTAGE_LEARNER_SERVICE_SECURITY_H_
