#include "learner/run/run_directory.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "common/util/cpu_model.h"

namespace vantage {

absl::Status WriteFileAtomically(const std::string& path,
                                 const std::string& text) {
  const std::string temporary = path + ".tmp";
  {
    std::ofstream file(temporary, std::ios::trunc);
    file << text;
    file.flush();
    if (!file) {
      return absl::InternalError(absl::StrCat("cannot write ", temporary));
    }
  }
  if (std::rename(temporary.c_str(), path.c_str()) != 0) {
    return absl::InternalError(
        absl::StrCat("cannot rename ", temporary, " to ", path));
  }
  return absl::OkStatus();
}

absl::Status RunDirectory::CheckFree(const std::string& path) {
  if (std::filesystem::exists(RunDirectory(path).config_path())) {
    return absl::AlreadyExistsError(absl::StrCat(
        path, " already holds a run; continue it with --resume=", path,
        " or choose another --run_dir"));
  }
  return absl::OkStatus();
}

absl::Status RunDirectory::Clear(const std::string& path) {
  for (const char* name : {"config.json", "progress.csv", "machine.json",
                           "checkpoints", "launch"}) {
    std::error_code error;
    std::filesystem::remove_all(absl::StrCat(path, "/", name), error);
    if (error) {
      return absl::InternalError(absl::StrCat("cannot remove ", path, "/", name,
                                              ": ", error.message()));
    }
  }
  return absl::OkStatus();
}

absl::StatusOr<RunDirectory> RunDirectory::Create(
    const std::string& path, const std::string& config_json) {
  if (absl::Status status = CheckFree(path); !status.ok()) return status;
  RunDirectory run(path);
  std::error_code error;
  std::filesystem::create_directories(run.checkpoint_directory(), error);
  if (error) {
    return absl::InvalidArgumentError(absl::StrCat(
        "cannot create run directory ", path, ": ", error.message()));
  }
  if (absl::Status status = WriteFileAtomically(
          run.progress_path(), absl::StrCat(ProgressHeader(), "\n"));
      !status.ok()) {
    return status;
  }
  if (absl::Status status = WriteFileAtomically(run.config_path(), config_json);
      !status.ok()) {
    return status;
  }
  return run;
}

absl::StatusOr<RunDirectory> RunDirectory::Open(const std::string& path) {
  RunDirectory run(path);
  if (!std::filesystem::is_regular_file(run.config_path())) {
    return absl::NotFoundError(
        absl::StrCat(path, " is not a run directory (no config.json)"));
  }
  return run;
}

std::string RunDirectory::config_path() const { return path_ + "/config.json"; }
std::string RunDirectory::progress_path() const {
  return path_ + "/progress.csv";
}
std::string RunDirectory::checkpoint_directory() const {
  return path_ + "/checkpoints";
}

std::string RunDirectory::machine_path() const {
  return path_ + "/machine.json";
}

absl::Status RunDirectory::RecordMachine() const {
  // One model per line between the brackets, as this function writes them.
  std::vector<std::string> models;
  std::ifstream file(machine_path());
  std::string line;
  while (std::getline(file, line)) {
    const size_t open = line.find('"');
    const size_t close = line.rfind('"');
    if (line.rfind("  \"", 0) == 0 && close > open) {
      models.push_back(line.substr(open + 1, close - open - 1));
    }
  }
  const std::string model = CpuModel();
  if (std::find(models.begin(), models.end(), model) != models.end()) {
    return absl::OkStatus();
  }
  models.push_back(model);
  std::vector<std::string> quoted;
  for (const std::string& m : models)
    quoted.push_back(absl::StrCat("  \"", m, "\""));
  return WriteFileAtomically(
      machine_path(), absl::StrCat("{\"cpu_models\": [\n",
                                   absl::StrJoin(quoted, ",\n"), "\n]}\n"));
}

std::vector<ProgressLine> ReadProgressLines(const std::string& run_dir) {
  std::ifstream file(RunDirectory(run_dir).progress_path());
  std::vector<ProgressLine> rows;
  std::string line;
  if (!std::getline(file, line)) return rows;
  const size_t columns =
      std::vector<absl::string_view>(absl::StrSplit(line, ',')).size();
  while (std::getline(file, line)) {
    const std::vector<absl::string_view> fields = absl::StrSplit(line, ',');
    ProgressLine row;
    if (fields.size() != columns || columns < 2 ||
        !absl::SimpleAtoi(fields[0], &row.env_steps) ||
        !absl::SimpleAtoi(fields[1], &row.updates)) {
      break;  // a torn last line from a crash
    }
    row.text = line;
    rows.push_back(std::move(row));
  }
  return rows;
}

absl::Status RunDirectory::TruncateProgress(int64_t updates) const {
  const std::string header = ProgressHeader();
  std::string text = absl::StrCat(header, "\n");
  // A file written by a vantage with other columns is carried over column
  // by column (a column it lacked stays empty), so resumed rows line up.
  std::ifstream file(progress_path());
  std::string old_header;
  std::getline(file, old_header);
  const std::vector<std::string> old_names = absl::StrSplit(old_header, ',');
  const std::vector<std::string> names = absl::StrSplit(header, ',');
  for (const ProgressLine& row : ReadProgressLines(path_)) {
    if (row.updates > updates) break;
    if (old_header == header) {
      absl::StrAppend(&text, row.text, "\n");
      continue;
    }
    const std::vector<std::string> values = absl::StrSplit(row.text, ',');
    std::vector<std::string> fields;
    for (const std::string& name : names) {
      const auto at = std::find(old_names.begin(), old_names.end(), name);
      fields.push_back(
          at == old_names.end()
              ? ""
              : values[static_cast<size_t>(at - old_names.begin())]);
    }
    absl::StrAppend(&text, absl::StrJoin(fields, ","), "\n");
  }
  return WriteFileAtomically(progress_path(), text);
}

absl::Status RunDirectory::AppendProgress(const ProgressRow& row) const {
  std::ofstream file(progress_path(), std::ios::app);
  file << FormatProgressRow(row) << "\n";
  file.flush();
  if (!file) {
    return absl::InternalError(
        absl::StrCat("cannot append to ", progress_path()));
  }
  return absl::OkStatus();
}

}  // namespace vantage
