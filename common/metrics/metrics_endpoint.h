#ifndef VANTAGE_COMMON_METRICS_METRICS_ENDPOINT_H_
#define VANTAGE_COMMON_METRICS_METRICS_ENDPOINT_H_

// The HTTP endpoint (GET /metrics) through which a process's Prometheus
// registry is scraped; the learner's and the actor's metrics both serve
// through it.

#include <memory>
#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace prometheus {
class Collectable;
class Exposer;
}  // namespace prometheus

namespace vantage {

struct MetricsEndpointOptions {
  // "IP:PORT" or just "PORT" (then 127.0.0.1: the endpoint is private to
  // the machine unless an address says otherwise); port 0 lets the OS pick.
  std::string address;
  // If set, an endpoint bound beyond loopback answers only requests with
  // HTTP basic auth user "vantage" and this password (Prometheus:
  // basic_auth with password_file = the run's token file).
  std::string auth_token;
};

// "9100" -> "127.0.0.1:9100"; anything else unchanged.
std::string ResolveMetricsAddress(absl::string_view address);
// Whether `address` (after ResolveMetricsAddress) binds only loopback.
bool IsLoopbackAddress(absl::string_view address);

// Serves `registry` (which must outlive the endpoint). An address that
// cannot be bound is an Unavailable error naming it and `who`.
absl::StatusOr<std::unique_ptr<prometheus::Exposer>> StartMetricsEndpoint(
    const MetricsEndpointOptions& options,
    std::weak_ptr<prometheus::Collectable> registry, absl::string_view who);

// The port an endpoint listens on (0 if none).
int MetricsPort(const prometheus::Exposer& exposer);

}  // namespace vantage

#endif  // VANTAGE_COMMON_METRICS_METRICS_ENDPOINT_H_
