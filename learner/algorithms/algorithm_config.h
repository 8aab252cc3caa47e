#ifndef VANTAGE_LEARNER_ALGORITHMS_ALGORITHM_CONFIG_H_
#define VANTAGE_LEARNER_ALGORITHMS_ALGORITHM_CONFIG_H_

// The algorithms' settings and how a run config names them, without
// LibTorch (the updaters are in learner/algorithms/algorithm.h).

#include <any>
#include <map>
#include <string>
#include <typeindex>
#include <vector>

#include "absl/status/status.h"
#include "learner/algorithms/run_defaults.h"

namespace vantage {
namespace pb {
class RunConfig;
}  // namespace pb

// Which algorithm updates the networks, with the settings of any algorithm
// (only the named one's are used). Each algorithm's config is its
// folder's type (PpoConfig, A2cConfig, ...), kept by type, so that a new
// algorithm adds no member here.
struct AlgorithmConfig {
  std::string name = "ppo";  // see AlgorithmNames()

  // The settings of the algorithm whose config is `Config`: its defaults
  // until set.
  template <typename Config>
  const Config& Get() const {
    const auto found = settings_.find(typeid(Config));
    if (found == settings_.end()) {
      static const Config defaults;
      return defaults;
    }
    return std::any_cast<const Config&>(found->second);
  }
  template <typename Config>
  Config& Mutable() {
    std::any& settings = settings_[typeid(Config)];
    if (!settings.has_value()) settings = Config();
    return std::any_cast<Config&>(settings);
  }

  // An unknown name lists the valid ones.
  absl::Status Validate() const;

 private:
  std::map<std::type_index, std::any> settings_;
};

std::vector<std::string> AlgorithmNames();

// Whether the named algorithm steps the policy and the value network with
// one optimiser (PPO, A2C), which parameters shared by both need; TRPO
// fits its value network on its own.
bool AlgorithmStepsBothNetworksAtOnce(const AlgorithmConfig& config);

// What the named algorithm's defaults choose outside its own section.
AlgorithmRunDefaults RunDefaultsOf(const AlgorithmConfig& config);

// The algorithm section of a run config (its `algorithm` oneof, one field
// per algorithm, named as the algorithm).
// The algorithm a run config names; "ppo" when it names none.
std::string AlgorithmNameOf(const pb::RunConfig& run);
// Names `name` with no settings of its own; an unknown name lists the
// valid ones.
absl::Status SelectAlgorithm(const std::string& name, pb::RunConfig& run);
// The named algorithm's section over its defaults (not yet validated).
AlgorithmConfig AlgorithmConfigOf(const pb::RunConfig& run);
// Every field of the named algorithm's settings, into its section.
void SetAlgorithmSettings(const AlgorithmConfig& config, pb::RunConfig& run);

}  // namespace vantage

#endif  // VANTAGE_LEARNER_ALGORITHMS_ALGORITHM_CONFIG_H_
