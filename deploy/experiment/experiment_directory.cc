#include "deploy/experiment/experiment_directory.h"

#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "deploy/run/run_config.h"
#include "google/protobuf/io/coded_stream.h"
#include "google/protobuf/io/zero_copy_stream_impl_lite.h"
#include "google/protobuf/util/json_util.h"
#include "google/protobuf/util/message_differencer.h"
#include "google/protobuf/util/type_resolver_util.h"
#include "learner/checkpoint/checkpoint_files.h"
#include "learner/run/run_directory.h"

namespace vantage {
namespace {

constexpr char kTypeUrlPrefix[] = "type.googleapis.com";

// Map fields print in the order of their serialised entries, which
// protobuf leaves to its hash tables unless asked for a deterministic
// (key-sorted) encoding; without one, the records committed beside a
// grid's cells would change order every time the grid is run.
std::string JsonOf(const google::protobuf::Message& message) {
  std::string bytes;
  {
    google::protobuf::io::StringOutputStream stream(&bytes);
    google::protobuf::io::CodedOutputStream coded(&stream);
    coded.SetSerializationDeterministic(true);
    (void)message.SerializeToCodedStream(&coded);
  }
  const google::protobuf::Descriptor& type = *message.GetDescriptor();
  const std::unique_ptr<google::protobuf::util::TypeResolver> resolver(
      google::protobuf::util::NewTypeResolverForDescriptorPool(
          kTypeUrlPrefix, type.file()->pool()));
  google::protobuf::util::JsonPrintOptions options;
  options.add_whitespace = true;
  options.preserve_proto_field_names = true;
  std::string json;
  // Messages of known types always print.
  (void)google::protobuf::util::BinaryToJsonString(
      resolver.get(), absl::StrCat(kTypeUrlPrefix, "/", type.full_name()),
      bytes, &json, options);
  return json;
}

// A run's settings as this vantage reads them: a setting added after the
// run was made is absent from its record and takes its default (a new
// setting's default keeps what older versions did), so a grid goes on
// with a newer binary; every setting the record holds is compared as held.
absl::StatusOr<pb::RunConfig> ReadNow(const pb::RunConfig& held) {
  return ResolveRunConfig(held);
}

}  // namespace

std::string ExpandedExperimentToJson(const pb::ExpandedExperiment& experiment) {
  return JsonOf(experiment);
}

std::string ExperimentDirectory::RunDir(const pb::ExperimentCell& cell) const {
  return absl::StrCat(path_, "/", cell.dir());
}

std::string ExperimentDirectory::LogPath(const pb::ExperimentCell& cell) const {
  return absl::StrCat(RunDir(cell), "/train.log");
}

std::string ExperimentDirectory::BaseConfigPath() const {
  return path_ + "/base.json";
}

std::string ExperimentDirectory::ExperimentPath() const {
  return path_ + "/experiment.json";
}

absl::Status ExperimentDirectory::CheckRuns(
    const pb::ExpandedExperiment& experiment) const {
  for (const pb::ExperimentCell& cell : experiment.cells()) {
    const std::string config_path = RunDir(cell) + "/config.json";
    if (!std::filesystem::exists(config_path)) continue;
    absl::StatusOr<pb::RunConfig> held = ReadRunConfigFile(config_path);
    if (held.ok()) held = ReadNow(*held);
    if (!held.ok()) {
      return absl::FailedPreconditionError(
          absl::StrCat(RunDir(cell),
                       " holds a run this experiment cannot "
                       "read: ",
                       held.status().message()));
    }
    if (!google::protobuf::util::MessageDifferencer::Equals(*held,
                                                            cell.config())) {
      return absl::FailedPreconditionError(absl::StrCat(
          RunDir(cell),
          " holds a run made with other settings than this experiment's "
          "cell (",
          RunConfigDifference(cell.config(), *held),
          "): the experiment file or --budget changed; use another --out "
          "or remove that run"));
    }
  }
  return absl::OkStatus();
}

absl::StatusOr<pb::ExpandedExperiment> ExperimentDirectory::Merged(
    const pb::ExpandedExperiment& experiment) const {
  std::ifstream file(ExperimentPath());
  if (!file) return experiment;
  std::stringstream text;
  text << file.rdbuf();
  pb::ExpandedExperiment held;
  if (!google::protobuf::util::JsonStringToMessage(text.str(), &held).ok()) {
    return absl::FailedPreconditionError(absl::StrCat(
        ExperimentPath(), " is not an experiment record; use another --out"));
  }
  if (held.budget() != experiment.budget()) {
    return absl::FailedPreconditionError(absl::StrCat(
        path_, " holds cells run at --budget=", held.budget(),
        "; this run asks for ", experiment.budget(), ": use another --out"));
  }
  std::map<std::string, const pb::ExperimentCell*> fresh;
  for (const pb::ExperimentCell& cell : experiment.cells()) {
    fresh[cell.dir()] = &cell;
  }
  pb::ExpandedExperiment merged = experiment;
  merged.clear_cells();
  for (const pb::ExperimentCell& cell : held.cells()) {
    const auto it = fresh.find(cell.dir());
    if (it == fresh.end()) {
      *merged.add_cells() = cell;
      continue;
    }
    absl::StatusOr<pb::RunConfig> held_config = ReadNow(cell.config());
    if (!held_config.ok()) {
      return absl::FailedPreconditionError(
          absl::StrCat(ExperimentPath(), " records ", cell.dir(),
                       " with settings this vantage refuses: ",
                       held_config.status().message()));
    }
    if (!google::protobuf::util::MessageDifferencer::Equals(
            *held_config, it->second->config())) {
      return absl::FailedPreconditionError(
          absl::StrCat(ExperimentPath(), " records ", cell.dir(),
                       " with other settings than this experiment's cell (",
                       RunConfigDifference(it->second->config(), *held_config),
                       "): use another --out"));
    }
    *merged.add_cells() = *it->second;
    fresh.erase(it);
  }
  for (const pb::ExperimentCell& cell : experiment.cells()) {
    if (fresh.count(cell.dir()) > 0) *merged.add_cells() = cell;
  }
  return merged;
}

absl::Status ExperimentDirectory::Prepare(
    const pb::ExpandedExperiment& experiment, const pb::RunConfig& base) const {
  if (absl::Status status = CheckRuns(experiment); !status.ok()) return status;
  absl::StatusOr<pb::ExpandedExperiment> merged = Merged(experiment);
  if (!merged.ok()) return merged.status();
  std::error_code error;
  std::filesystem::create_directories(path_, error);
  if (error) {
    return absl::FailedPreconditionError(absl::StrCat(
        "cannot create experiment directory ", path_, ": ", error.message()));
  }
  if (absl::Status status = WriteFileAtomically(BaseConfigPath(), JsonOf(base));
      !status.ok()) {
    return status;
  }
  return WriteFileAtomically(ExperimentPath(),
                             ExpandedExperimentToJson(*merged));
}

int64_t LastProgressSteps(const std::string& run_dir) {
  const std::vector<ProgressLine> rows = ReadProgressLines(run_dir);
  return rows.empty() ? 0 : rows.back().env_steps;
}

CellStatus ExperimentDirectory::Inspect(const pb::ExperimentCell& cell) const {
  CellStatus status;
  const std::string run_dir = RunDir(cell);
  if (!std::filesystem::exists(run_dir + "/config.json")) return status;
  status.env_steps = LastProgressSteps(run_dir);
  if (status.env_steps >= cell.config().training().steps()) {
    status.state = CellState::kFinished;
  } else if (!ListCheckpoints(run_dir + "/checkpoints").empty()) {
    status.state = CellState::kResumable;
  } else {
    status.state = CellState::kNoCheckpoint;
  }
  return status;
}

absl::Status ExperimentDirectory::ClearRun(
    const pb::ExperimentCell& cell) const {
  return RunDirectory::Clear(RunDir(cell));
}

std::string LastLogLine(const std::string& log_path) {
  std::ifstream file(log_path);
  std::string line;
  std::string last;
  while (std::getline(file, line)) {
    if (!line.empty()) last = line;
  }
  return last;
}

}  // namespace vantage
