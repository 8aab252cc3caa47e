#include "learner/algorithms/algorithm.h"

#include <functional>
#include <map>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"

namespace vantage {
namespace {

struct Algorithm {
  std::function<absl::Status(const AlgorithmConfig&)> validate;
  std::function<std::unique_ptr<PolicyUpdater>(const AlgorithmConfig&,
                                               PolicyNetwork, ValueNetwork)>
      make;
};

const std::map<std::string, Algorithm>& Algorithms() {
  static const auto* algorithms = new std::map<std::string, Algorithm>{
      {"a2c",
       {[](const AlgorithmConfig& c) { return c.a2c.Validate(); },
        [](const AlgorithmConfig& c, PolicyNetwork p, ValueNetwork v) {
          return std::make_unique<A2cUpdater>(p, v, c.a2c);
        }}},
      {"ppo",
       {[](const AlgorithmConfig& c) { return c.ppo.Validate(); },
        [](const AlgorithmConfig& c, PolicyNetwork p, ValueNetwork v) {
          return std::make_unique<PpoUpdater>(p, v, c.ppo);
        }}},
      {"trpo",
       {[](const AlgorithmConfig& c) { return c.trpo.Validate(); },
        [](const AlgorithmConfig& c, PolicyNetwork p, ValueNetwork v) {
          return std::make_unique<TrpoUpdater>(p, v, c.trpo);
        }}},
  };
  return *algorithms;
}

}  // namespace

std::vector<std::string> AlgorithmNames() {
  std::vector<std::string> names;
  for (const auto& entry : Algorithms()) names.push_back(entry.first);
  return names;
}

absl::Status AlgorithmConfig::Validate() const {
  const auto algorithm = Algorithms().find(name);
  if (algorithm != Algorithms().end()) return algorithm->second.validate(*this);
  return absl::InvalidArgumentError(
      absl::StrCat("unknown algorithm '", name,
                   "'; available: ", absl::StrJoin(AlgorithmNames(), ", ")));
}

absl::StatusOr<std::unique_ptr<PolicyUpdater>> MakePolicyUpdater(
    const AlgorithmConfig& config, PolicyNetwork policy, ValueNetwork value) {
  if (absl::Status status = config.Validate(); !status.ok()) return status;
  return Algorithms()
      .at(config.name)
      .make(config, std::move(policy), std::move(value));
}

}  // namespace vantage
