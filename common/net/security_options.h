#ifndef VANTAGE_COMMON_NET_SECURITY_OPTIONS_H_
#define VANTAGE_COMMON_NET_SECURITY_OPTIONS_H_

// What secures the actor-learner connection, for both ends: the learner
// serves with it, actors dial with it. Plain settings and their checks;
// common/net/grpc_security.h turns them into gRPC credentials.

#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"

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

// The whole of a file (a PEM file, a token); errors name `what` and `path`.
absl::StatusOr<std::string> ReadSecurityFile(const std::string& path,
                                             const std::string& what);

// Incomplete TLS settings are errors that name the missing flag.
absl::Status ValidateServerSecurity(const SecurityOptions& options);
absl::Status ValidateClientSecurity(const SecurityOptions& options);

}  // namespace vantage

#endif  // VANTAGE_COMMON_NET_SECURITY_OPTIONS_H_
