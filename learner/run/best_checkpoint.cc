#include "learner/run/best_checkpoint.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <system_error>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "learner/run/run_directory.h"

namespace vantage {
namespace {

namespace fs = std::filesystem;

constexpr char kHeldPrefix[] = "evaluating-";

// best.json's eval_return, or NaN without one; a file that says nothing
// readable is an error naming it (a best.pt then has no known return).
absl::StatusOr<double> ReadBestReturn(const std::string& path) {
  std::ifstream file(path);
  if (!file) return std::numeric_limits<double>::quiet_NaN();
  std::stringstream text;
  text << file.rdbuf();
  const std::string json = text.str();
  const std::string key = "\"eval_return\":";
  const size_t at = json.find(key);
  double value = 0.0;
  if (at == std::string::npos ||
      std::sscanf(json.c_str() + at + key.size(), "%lf", &value) != 1 ||
      !std::isfinite(value)) {
    return absl::DataLossError(
        absl::StrCat(path, " holds no finite \"eval_return\""));
  }
  return value;
}

}  // namespace

absl::StatusOr<BestCheckpoint> BestCheckpoint::Open(
    const std::string& directory) {
  BestCheckpoint best(directory);
  absl::StatusOr<double> value = ReadBestReturn(directory + "/best.json");
  if (!value.ok()) return value.status();
  best.best_return_ = *value;
  best.ReleaseBefore(std::numeric_limits<int64_t>::max());
  return best;
}

std::string BestCheckpoint::best_path() const {
  return directory_ + "/best.pt";
}

std::string BestCheckpoint::held_path(int64_t version) const {
  return absl::StrFormat("%s/%s%08d.pt", directory_, kHeldPrefix, version);
}

absl::Status BestCheckpoint::Hold(const std::string& checkpoint_path,
                                  int64_t version) {
  std::error_code error;
  fs::remove(held_path(version), error);
  fs::create_hard_link(checkpoint_path, held_path(version), error);
  // A file system without hard links gets a copy.
  if (error) {
    error.clear();
    fs::copy_file(checkpoint_path, held_path(version), error);
  }
  if (error) {
    return absl::InternalError(
        absl::StrCat("cannot link or copy ", checkpoint_path, " as ",
                     held_path(version), ": ", error.message()));
  }
  return absl::OkStatus();
}

void BestCheckpoint::ReleaseBefore(int64_t version) {
  std::error_code error;
  for (const fs::directory_entry& entry :
       fs::directory_iterator(directory_, error)) {
    const std::string name = entry.path().filename().string();
    int64_t held = 0;
    if (absl::StartsWith(name, kHeldPrefix) &&
        std::sscanf(name.c_str() + sizeof(kHeldPrefix) - 1, "%ld", &held) ==
            1 &&
        held < version) {
      fs::remove(entry.path(), error);
    }
  }
}

absl::StatusOr<bool> BestCheckpoint::Offer(
    const EvaluationSummary& evaluation) {
  // Evaluations come in version order: the held versions before this one
  // were dropped unevaluated.
  ReleaseBefore(evaluation.version);
  const std::string held = held_path(evaluation.version);
  std::error_code error;
  if (!fs::exists(held, error)) {
    return absl::NotFoundError(
        absl::StrCat("no checkpoint of version ", evaluation.version,
                     " is held for its evaluation (", held, ")"));
  }
  const bool better =
      std::isfinite(evaluation.mean) &&
      (std::isnan(best_return_) || evaluation.mean > best_return_);
  if (!better) {
    fs::remove(held, error);
    return false;
  }
  // The record first: a crash between the two can leave best.pt one
  // version behind best.json, but never lets a worse version replace it.
  if (absl::Status status = WriteFileAtomically(
          directory_ + "/best.json",
          absl::StrFormat("{\"version\": %d, \"eval_return\": %.9g, "
                          "\"eval_return_std\": %.9g, \"eval_return_min\": "
                          "%.9g, \"eval_return_max\": %.9g}\n",
                          evaluation.version, evaluation.mean, evaluation.std,
                          evaluation.min, evaluation.max));
      !status.ok()) {
    return status;
  }
  fs::rename(held, best_path(), error);
  if (error) {
    return absl::InternalError(absl::StrCat(
        "cannot rename ", held, " to ", best_path(), ": ", error.message()));
  }
  best_return_ = evaluation.mean;
  return true;
}

}  // namespace vantage
