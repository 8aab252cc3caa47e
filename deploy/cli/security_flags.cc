#include "deploy/cli/security_flags.h"

#include "absl/flags/flag.h"

ABSL_FLAG(std::string, auth_token_file, "",
          "a file holding the shared token every RPC must carry; empty: none");
ABSL_FLAG(std::string, tls_cert, "",
          "learner: its TLS certificate (PEM, with --tls_key); actor: its "
          "client certificate");
ABSL_FLAG(std::string, tls_key, "",
          "learner: the private key of --tls_cert (PEM); actor: the client "
          "certificate's key");
ABSL_FLAG(std::string, tls_ca, "",
          "actor: TLS with this CA (PEM) verifying the learner; learner: "
          "clients must present a certificate this CA signed");

namespace vantage {

std::vector<std::string> SecurityFlagNames() {
  return {"auth_token_file", "tls_cert", "tls_key", "tls_ca"};
}

std::string AuthTokenFileFlag() { return absl::GetFlag(FLAGS_auth_token_file); }

absl::StatusOr<SecurityOptions> SecurityFromFlags(bool server) {
  SecurityOptions security;
  security.tls_cert_file = absl::GetFlag(FLAGS_tls_cert);
  security.tls_key_file = absl::GetFlag(FLAGS_tls_key);
  security.tls_ca_file = absl::GetFlag(FLAGS_tls_ca);
  if (absl::Status status = server ? ValidateServerSecurity(security)
                                   : ValidateClientSecurity(security);
      !status.ok()) {
    return status;
  }
  if (!absl::GetFlag(FLAGS_auth_token_file).empty()) {
    absl::StatusOr<std::string> token =
        ReadTokenFile(absl::GetFlag(FLAGS_auth_token_file));
    if (!token.ok()) return token.status();
    security.auth_token = *std::move(token);
  }
  return security;
}

}  // namespace vantage
