#include "learner/algorithms/algorithm.h"

#include <functional>
#include <map>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "learner/algorithms/a2c/a2c_updater.h"
#include "learner/algorithms/ppo/ppo_updater.h"
#include "learner/algorithms/trpo/trpo_updater.h"
#include "proto/run_config.pb.h"

namespace vantage {
namespace {

struct Algorithm {
  std::function<void(const pb::RunConfig&, AlgorithmConfig&)> read;
  std::function<void(const AlgorithmConfig&, pb::RunConfig&)> write;
  std::function<AlgorithmRunDefaults(const AlgorithmConfig&)> run_defaults;
  std::function<absl::Status(const AlgorithmConfig&)> validate;
  std::function<std::unique_ptr<PolicyUpdater>(const AlgorithmConfig&,
                                               PolicyNetwork, ValueNetwork,
                                               std::shared_ptr<ReplicaGroup>)>
      make;
  // One optimiser steps the policy and the value network together, so the
  // two may share parameters.
  bool one_optimizer = false;
};

// An algorithm whose updater is Updater, whose config is Config and whose
// settings are the run config's section `get`/`set`; its config header
// declares Validate(), RunDefaults(), FromSettings() and ToSettings().
template <typename Updater, typename Config, typename Settings>
Algorithm Entry(const Settings& (pb::RunConfig::*get)() const,
                Settings* (pb::RunConfig::*set)()) {
  Algorithm algorithm;
  algorithm.read = [=](const pb::RunConfig& run, AlgorithmConfig& config) {
    config.Mutable<Config>() = FromSettings((run.*get)());
  };
  algorithm.write = [=](const AlgorithmConfig& config, pb::RunConfig& run) {
    ToSettings(config.Get<Config>(), *(run.*set)());
  };
  algorithm.run_defaults = [=](const AlgorithmConfig& config) {
    return RunDefaults(config.Get<Config>());
  };
  algorithm.validate = [=](const AlgorithmConfig& config) {
    return config.Get<Config>().Validate();
  };
  algorithm.make = [=](const AlgorithmConfig& config, PolicyNetwork policy,
                       ValueNetwork value,
                       std::shared_ptr<ReplicaGroup> replicas)
      -> std::unique_ptr<PolicyUpdater> {
    return std::make_unique<Updater>(std::move(policy), std::move(value),
                                     config.Get<Config>(), std::move(replicas));
  };
  algorithm.one_optimizer = Updater::kOneOptimizer;
  return algorithm;
}

// The name is also the run config's field of the algorithm's settings.
const std::map<std::string, Algorithm>& Algorithms() {
  static const auto* algorithms = new std::map<std::string, Algorithm>{
      {"a2c", Entry<A2cUpdater, A2cConfig>(&pb::RunConfig::a2c,
                                           &pb::RunConfig::mutable_a2c)},
      {"ppo", Entry<PpoUpdater, PpoConfig>(&pb::RunConfig::ppo,
                                           &pb::RunConfig::mutable_ppo)},
      {"trpo", Entry<TrpoUpdater, TrpoConfig>(&pb::RunConfig::trpo,
                                              &pb::RunConfig::mutable_trpo)},
  };
  return *algorithms;
}

absl::Status UnknownAlgorithm(const std::string& name) {
  return absl::InvalidArgumentError(
      absl::StrCat("unknown algorithm '", name,
                   "'; available: ", absl::StrJoin(AlgorithmNames(), ", ")));
}

}  // namespace

std::vector<std::string> AlgorithmNames() {
  std::vector<std::string> names;
  for (const auto& entry : Algorithms()) names.push_back(entry.first);
  return names;
}

absl::Status AlgorithmConfig::Validate() const {
  const auto algorithm = Algorithms().find(name);
  if (algorithm == Algorithms().end()) return UnknownAlgorithm(name);
  return algorithm->second.validate(*this);
}

absl::StatusOr<std::unique_ptr<PolicyUpdater>> MakePolicyUpdater(
    const AlgorithmConfig& config, PolicyNetwork policy, ValueNetwork value,
    std::shared_ptr<ReplicaGroup> replicas) {
  if (absl::Status status = config.Validate(); !status.ok()) return status;
  return Algorithms()
      .at(config.name)
      .make(config, std::move(policy), std::move(value), std::move(replicas));
}

bool AlgorithmStepsBothNetworksAtOnce(const AlgorithmConfig& config) {
  const auto algorithm = Algorithms().find(config.name);
  return algorithm != Algorithms().end() && algorithm->second.one_optimizer;
}

AlgorithmRunDefaults RunDefaultsOf(const AlgorithmConfig& config) {
  const auto algorithm = Algorithms().find(config.name);
  if (algorithm == Algorithms().end()) return AlgorithmRunDefaults();
  return algorithm->second.run_defaults(config);
}

std::string AlgorithmNameOf(const pb::RunConfig& run) {
  const auto* oneof = run.GetDescriptor()->FindOneofByName("algorithm");
  const auto* field = run.GetReflection()->GetOneofFieldDescriptor(run, oneof);
  return field == nullptr ? "ppo" : field->name();
}

absl::Status SelectAlgorithm(const std::string& name, pb::RunConfig& run) {
  const auto* field = run.GetDescriptor()->FindFieldByName(name);
  if (Algorithms().count(name) == 0 || field == nullptr ||
      field->containing_oneof() == nullptr) {
    return UnknownAlgorithm(name);
  }
  run.GetReflection()->MutableMessage(&run, field);
  return absl::OkStatus();
}

AlgorithmConfig AlgorithmConfigOf(const pb::RunConfig& run) {
  AlgorithmConfig config;
  config.name = AlgorithmNameOf(run);
  const auto algorithm = Algorithms().find(config.name);
  if (algorithm != Algorithms().end()) algorithm->second.read(run, config);
  return config;
}

void SetAlgorithmSettings(const AlgorithmConfig& config, pb::RunConfig& run) {
  const auto algorithm = Algorithms().find(config.name);
  if (algorithm != Algorithms().end()) algorithm->second.write(config, run);
}

}  // namespace vantage
