#include "common/net/security_options.h"

#include <fstream>
#include <sstream>

#include "absl/strings/str_cat.h"
#include "absl/strings/strip.h"

namespace vantage {

absl::StatusOr<std::string> ReadSecurityFile(const std::string& path,
                                             const std::string& what) {
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

absl::StatusOr<std::string> ReadTokenFile(const std::string& path) {
  absl::StatusOr<std::string> contents = ReadSecurityFile(path, "auth token");
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

}  // namespace vantage
