#ifndef VANTAGE_COMMON_METRICS_METRICS_REGISTRY_H_
#define VANTAGE_COMMON_METRICS_METRICS_REGISTRY_H_

// A process's Prometheus metrics and the endpoint they are scraped from.
// The actor's and the learner's metrics each own one and add their series
// to it under their prefix ("vantage_actor_", "vantage_learner_"), so the
// registry, its lifetime against the endpoint's threads and the rules for
// feeding counters exist once.

#include <cstdint>
#include <memory>
#include <string>

#include "absl/status/status.h"
#include "absl/strings/string_view.h"
#include "common/metrics/metrics_endpoint.h"
#include "common/util/running_total.h"
#include "prometheus/counter.h"
#include "prometheus/family.h"
#include "prometheus/gauge.h"
#include "prometheus/histogram.h"

namespace prometheus {
class Registry;
}  // namespace prometheus

namespace vantage {

class MetricsRegistry {
 public:
  explicit MetricsRegistry(std::string prefix);
  ~MetricsRegistry();
  MetricsRegistry(const MetricsRegistry&) = delete;
  MetricsRegistry& operator=(const MetricsRegistry&) = delete;

  // One series each, named prefix + name; they live as long as this.
  prometheus::Counter& AddCounter(const std::string& name,
                                  const std::string& help);
  prometheus::Gauge& AddGauge(const std::string& name, const std::string& help);
  prometheus::Histogram& AddHistogram(
      const std::string& name, const std::string& help,
      const prometheus::Histogram::BucketBoundaries& buckets);
  // A family whose series the caller adds by label.
  prometheus::Family<prometheus::Counter>& AddCounterFamily(
      const std::string& name, const std::string& help);
  prometheus::Family<prometheus::Gauge>& AddGaugeFamily(
      const std::string& name, const std::string& help);

  // Starts serving (see StartMetricsEndpoint); `who` names the process in
  // errors.
  absl::Status Serve(const MetricsEndpointOptions& options,
                     absl::string_view who);
  // The port served on (0 before Serve).
  int port() const;

 private:
  const std::string prefix_;
  // Declared before the exposer, so it outlives the exposer's threads.
  std::shared_ptr<prometheus::Registry> registry_;
  std::unique_ptr<prometheus::Exposer> exposer_;
};

// Adds `seconds` unless negative or not finite: a NaN increment would
// poison a counter for good, and prometheus-cpp itself only drops negative
// ones.
void AddSeconds(prometheus::Counter& counter, double seconds);

// A counter fed from a running total its owner keeps (RunningTotal): the
// same total twice, or an older one arriving late, adds nothing. Not
// thread-safe; the owner serialises calls.
class TotalCounter {
 public:
  explicit TotalCounter(prometheus::Counter& counter) : counter_(counter) {}
  void Record(int64_t total);

 private:
  prometheus::Counter& counter_;
  RunningTotal total_;
};

}  // namespace vantage

#endif  // VANTAGE_COMMON_METRICS_METRICS_REGISTRY_H_
