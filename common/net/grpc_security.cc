#include "common/net/grpc_security.h"

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/strip.h"
#include "common/util/constant_time.h"

namespace vantage {
namespace {

constexpr char kAuthorizationKey[] = "authorization";
constexpr char kBearerPrefix[] = "Bearer ";

struct CertificateAndKey {
  std::string certificate;
  std::string key;
};

absl::StatusOr<CertificateAndKey> ReadCertificateAndKey(
    const SecurityOptions& options) {
  absl::StatusOr<std::string> cert =
      ReadSecurityFile(options.tls_cert_file, "TLS certificate");
  if (!cert.ok()) return cert.status();
  absl::StatusOr<std::string> key =
      ReadSecurityFile(options.tls_key_file, "TLS key");
  if (!key.ok()) return key.status();
  return CertificateAndKey{*std::move(cert), *std::move(key)};
}

}  // namespace

absl::StatusOr<std::shared_ptr<grpc::ServerCredentials>> MakeServerCredentials(
    const SecurityOptions& options) {
  if (absl::Status status = ValidateServerSecurity(options); !status.ok()) {
    return status;
  }
  if (!options.tls()) return grpc::InsecureServerCredentials();
  absl::StatusOr<CertificateAndKey> own = ReadCertificateAndKey(options);
  if (!own.ok()) return own.status();
  grpc::SslServerCredentialsOptions ssl;
  ssl.pem_key_cert_pairs.push_back(
      {std::move(own->key), std::move(own->certificate)});
  if (!options.tls_ca_file.empty()) {
    absl::StatusOr<std::string> ca =
        ReadSecurityFile(options.tls_ca_file, "TLS CA");
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
    absl::StatusOr<std::string> ca =
        ReadSecurityFile(options.tls_ca_file, "TLS CA");
    if (!ca.ok()) return ca.status();
    ssl.pem_root_certs = *std::move(ca);
  }
  if (!options.tls_cert_file.empty()) {
    absl::StatusOr<CertificateAndKey> own = ReadCertificateAndKey(options);
    if (!own.ok()) return own.status();
    ssl.pem_cert_chain = std::move(own->certificate);
    ssl.pem_private_key = std::move(own->key);
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
