#ifndef VANTAGE_DEPLOY_OBSERVE_SCRAPE_TARGETS_H_
#define VANTAGE_DEPLOY_OBSERVE_SCRAPE_TARGETS_H_

// A run's Prometheus scrape targets as a file-based service discovery file
// (a JSON list of {"targets": ["HOST:PORT"], "labels": {...}}), which
// Prometheus re-reads when it changes: deploy/prometheus/ watches every
// run's file.

#include <map>
#include <string>
#include <vector>

#include "absl/status/status.h"

namespace vantage {

inline constexpr char kScrapeTargetsFile[] = "prometheus_targets.json";

struct ScrapeTarget {
  std::string address;  // HOST:PORT
  std::map<std::string, std::string> labels;
};

// The file's text; an empty list says "nothing to scrape".
std::string ScrapeTargetsJson(const std::vector<ScrapeTarget>& targets);
// Replaces `path` atomically (Prometheus never reads half a file).
absl::Status WriteScrapeTargets(const std::string& path,
                                const std::vector<ScrapeTarget>& targets);

// The address to scrape an endpoint bound on `host` ("127.0.0.1",
// "0.0.0.0", "[::1]", a name) at, once it serves on `port`: a wildcard
// bind is reached through this machine's host name, anything else as
// bound.
std::string ScrapeAddress(const std::string& host, int port);

}  // namespace vantage

#endif  // VANTAGE_DEPLOY_OBSERVE_SCRAPE_TARGETS_H_
