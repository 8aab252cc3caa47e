#include "common/metrics/metrics_registry.h"

#include <cmath>
#include <utility>

#include "prometheus/exposer.h"
#include "prometheus/registry.h"

namespace vantage {

MetricsRegistry::MetricsRegistry(std::string prefix)
    : prefix_(std::move(prefix)),
      registry_(std::make_shared<prometheus::Registry>()) {}

MetricsRegistry::~MetricsRegistry() = default;

prometheus::Counter& MetricsRegistry::AddCounter(const std::string& name,
                                                 const std::string& help) {
  return AddCounterFamily(name, help).Add({});
}

prometheus::Family<prometheus::Counter>& MetricsRegistry::AddCounterFamily(
    const std::string& name, const std::string& help) {
  return prometheus::BuildCounter()
      .Name(prefix_ + name)
      .Help(help)
      .Register(*registry_);
}

prometheus::Gauge& MetricsRegistry::AddGauge(const std::string& name,
                                             const std::string& help) {
  return AddGaugeFamily(name, help).Add({});
}

prometheus::Family<prometheus::Gauge>& MetricsRegistry::AddGaugeFamily(
    const std::string& name, const std::string& help) {
  return prometheus::BuildGauge()
      .Name(prefix_ + name)
      .Help(help)
      .Register(*registry_);
}

prometheus::Histogram& MetricsRegistry::AddHistogram(
    const std::string& name, const std::string& help,
    const prometheus::Histogram::BucketBoundaries& buckets) {
  return prometheus::BuildHistogram()
      .Name(prefix_ + name)
      .Help(help)
      .Register(*registry_)
      .Add({}, buckets);
}

absl::Status MetricsRegistry::Serve(const MetricsEndpointOptions& options,
                                    absl::string_view who) {
  absl::StatusOr<std::unique_ptr<prometheus::Exposer>> exposer =
      StartMetricsEndpoint(options, registry_, who);
  if (!exposer.ok()) return exposer.status();
  exposer_ = *std::move(exposer);
  return absl::OkStatus();
}

int MetricsRegistry::port() const {
  return exposer_ == nullptr ? 0 : MetricsPort(*exposer_);
}

void AddSeconds(prometheus::Counter& counter, double seconds) {
  if (std::isfinite(seconds) && seconds > 0) counter.Increment(seconds);
}

void TotalCounter::Record(int64_t total) {
  const int64_t increment = total_.Advance(total);
  if (increment > 0) counter_.Increment(static_cast<double>(increment));
}

}  // namespace vantage
