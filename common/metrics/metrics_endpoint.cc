#include "common/metrics/metrics_endpoint.h"

#include <algorithm>
#include <exception>
#include <vector>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/strip.h"
#include "common/util/constant_time.h"
#include "prometheus/exposer.h"

namespace vantage {
namespace {

constexpr char kUser[] = "vantage";

}  // namespace

std::string ResolveMetricsAddress(absl::string_view address) {
  absl::string_view port = address;
  absl::ConsumePrefix(&port, ":");
  const bool digits_only =
      !port.empty() && std::all_of(port.begin(), port.end(), [](char c) {
        return absl::ascii_isdigit(static_cast<unsigned char>(c));
      });
  if (digits_only) return absl::StrCat("127.0.0.1:", port);
  return std::string(address);
}

bool IsLoopbackAddress(absl::string_view address) {
  return absl::StartsWith(address, "127.") ||
         absl::StartsWith(address, "localhost:") ||
         absl::StartsWith(address, "[::1]:");
}

absl::StatusOr<std::unique_ptr<prometheus::Exposer>> StartMetricsEndpoint(
    const MetricsEndpointOptions& options,
    std::weak_ptr<prometheus::Collectable> registry, absl::string_view who) {
  const std::string address = ResolveMetricsAddress(options.address);
  if (address.empty()) {
    return absl::InvalidArgumentError(
        "the metrics address is empty (expected IP:PORT or PORT)");
  }
  std::unique_ptr<prometheus::Exposer> exposer;
  try {
    exposer = std::make_unique<prometheus::Exposer>(address);
  } catch (const std::exception& e) {
    // civetweb reports every failure to listen the same way.
    return absl::UnavailableError(absl::StrCat(
        "cannot serve ", who, " metrics on \"", address,
        "\" (in use, malformed, or not a local address; expected IP:PORT "
        "or PORT): ",
        e.what()));
  }
  if (!options.auth_token.empty() && !IsLoopbackAddress(address)) {
    exposer->RegisterAuth(
        [token = options.auth_token](const std::string& user,
                                     const std::string& password) {
          return user == kUser && ConstantTimeEquals(password, token);
        },
        "vantage");
  }
  exposer->RegisterCollectable(registry);
  return exposer;
}

int MetricsPort(const prometheus::Exposer& exposer) {
  const std::vector<int> ports = exposer.GetListeningPorts();
  return ports.empty() ? 0 : ports.front();
}

}  // namespace vantage
