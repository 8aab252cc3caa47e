#include "deploy/experiment/experiment_backend.h"

#include <functional>
#include <map>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "deploy/experiment/local_backend.h"
#include "deploy/experiment/slurm_backend.h"

namespace vantage {
namespace {

using BackendFactory =
    std::function<absl::StatusOr<std::unique_ptr<ExperimentBackend>>(
        const BackendOptions&)>;

const std::map<std::string, BackendFactory>& Backends() {
  static const auto* backends = new std::map<std::string, BackendFactory>{
      {"local", MakeLocalBackend},
      {"slurm", MakeSlurmBackend},
  };
  return *backends;
}

}  // namespace

std::vector<std::string> ExperimentBackendNames() {
  std::vector<std::string> names;
  for (const auto& [name, factory] : Backends()) names.push_back(name);
  return names;
}

absl::StatusOr<std::unique_ptr<ExperimentBackend>> MakeExperimentBackend(
    const std::string& name, const BackendOptions& options) {
  const auto it = Backends().find(name);
  if (it == Backends().end()) {
    return absl::InvalidArgumentError(absl::StrCat(
        "unknown backend '", name,
        "'; backends: ", absl::StrJoin(ExperimentBackendNames(), ", ")));
  }
  return it->second(options);
}

}  // namespace vantage
