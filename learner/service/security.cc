#include "learner/service/security.h"

#include <fstream>
#include <sstream>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/strip.h"

namespace vantage {
namespace {

constexpr char kAuthorizationKey[] = "authorization";
constexpr char kBearerPrefix[] = "Bearer ";

absl::StatusOr<std::string> ReadFile(const std::string& path,
                                     absl::string_view what) {
  std::ifstream file(path, std::ios::binary);
  if (!file) {
    return absl::NotFoundError(
        absl::StrCat("cannot read the ", what, " file ", path));
  }
  std::ostringstream contents;
  contents << file.rdbuf();
  if (file.bad()) {
    return absl::DataLossError(
        absl::StrCat("error reading the ", what, " file ", path));
  }
  return contents.str();
}

}  // namespace

absl::StatusOr<std::string> ReadTokenFile(const std::string& path) {
  absl::StatusOr<std::string> contents = ReadFile(path, "auth token");
  if (!contents.ok()) return contents.status();
  absl::string_view token = *contents;
  // Editors and `echo` end the file with a newline that is not the token's.
  absl::ConsumeSuffix(&token, "\n");
  absl::ConsumeSuffix(&token, "\r");
  if (token.empty()) {
    return absl::InvalidArgumentError(
        absl::StrCat("the auth token file ", path, " is empty"));
  }
  return std::string(token);
}

absl::Status ValidateServerSecurity(const SecurityOptions& options) {
  if (options.tls_cert_file.empty() != options.tls_key_file.empty()) {
    return absl::InvalidArgumentError(
        "TLS needs both --tls_cert and --tls_key (the learner's certificate "
        "and its private key)");
  }
  if (!options.tls_ca_file.empty() && options.tls_cert_file.empty()) {
    return absl::InvalidArgumentError(
        "--tls_ca on the learner verifies client certificates and needs TLS: "
        "give --tls_cert and --tls_key too");
  }
  return absl::OkStatus();
}

absl::Status ValidateClientSecurity(const SecurityOptions& options) {
  if (options.tls_cert_file.empty() != options.tls_key_file.empty()) {
    return absl::InvalidArgumentError(
        "a client certificate needs both --tls_cert and --tls_key");
  }
  return absl::OkStatus();
}

absl::StatusOr<std::shared_ptr<grpc::ServerCredentials>> MakeServerCredentials(
    const SecurityOptions& options) {
  if (absl::Status status = ValidateServerSecurity(options); !status.ok()) {
    return status;
  }
  if (!options.tls()) return grpc::InsecureServerCredentials();
  absl::StatusOr<std::string> cert =
      ReadFile(options.tls_cert_file, "TLS certificate");
  if (!cert.ok()) return cert.status();
  absl::StatusOr<std::string> key = ReadFile(options.tls_key_file, "TLS key");
  if (!key.ok()) return key.status();
  grpc::SslServerCredentialsOptions ssl;
  ssl.pem_key_cert_pairs.push_back({*std::move(key), *std::move(cert)});
  if (!options.tls_ca_file.empty()) {
    absl::StatusOr<std::string> ca = ReadFile(options.tls_ca_file, "TLS CA");
    if (!ca.ok()) return ca.status();
    ssl.pem_root_certs = *std::move(ca);
    ssl.client_certificate_request =
        GRPC_SSL_REQUEST_AND_REQUIRE_CLIENT_CERTIFICATE_AND_VERIFY;
  }
  return grpc::SslServerCredentials(ssl);
}

absl::StatusOr<std::shared_ptr<grpc::ChannelCredentials>>
MakeChannelCredentials(const SecurityOptions& options) {
  if (absl::Status status = ValidateClientSecurity(options); !status.ok()) {
    return status;
  }
  if (!options.tls()) return grpc::InsecureChannelCredentials();
  grpc::SslCredentialsOptions ssl;
  if (!options.tls_ca_file.empty()) {
    absl::StatusOr<std::string> ca = ReadFile(options.tls_ca_file, "TLS CA");
    if (!ca.ok()) return ca.status();
    ssl.pem_root_certs = *std::move(ca);
  }
  if (!options.tls_cert_file.empty()) {
    absl::StatusOr<std::string> cert =
        ReadFile(options.tls_cert_file, "TLS certificate");
    if (!cert.ok()) return cert.status();
    absl::StatusOr<std::string> key = ReadFile(options.tls_key_file, "TLS key");
    if (!key.ok()) return key.status();
    ssl.pem_cert_chain = *std::move(cert);
    ssl.pem_private_key = *std::move(key);
  }
  return grpc::SslCredentials(ssl);
}

// Per call rather than as call credentials: gRPC refuses to compose call
// credentials with insecure channel credentials, and one path serves both.
void AddAuthToken(const SecurityOptions& options,
                  grpc::ClientContext& context) {
  if (options.auth_token.empty()) return;
  context.AddMetadata(kAuthorizationKey,
                      absl::StrCat(kBearerPrefix, options.auth_token));
}

// Checked in the service's methods rather than by an AuthMetadataProcessor:
// gRPC 1.51 aborts when one is set on insecure server credentials
// (GPR_ASSERT in InsecureServerCredentials), and a server interceptor cannot
// fail a call with a status of its choosing.
grpc::Status CheckAuthToken(const grpc::ServerContext& context,
                            absl::string_view token) {
  if (token.empty()) return grpc::Status::OK;
  const auto& metadata = context.client_metadata();
  bool valid = false;
  for (auto [it, end] = metadata.equal_range(kAuthorizationKey); it != end;
       ++it) {
    absl::string_view value(it->second.data(), it->second.size());
    if (absl::ConsumePrefix(&value, kBearerPrefix) &&
        ConstantTimeEquals(value, token)) {
      valid = true;
    }
  }
  if (valid) return grpc::Status::OK;
  return grpc::Status(grpc::StatusCode::UNAUTHENTICATED,
                      "missing or wrong auth token");
}

}  // namespace vantage
