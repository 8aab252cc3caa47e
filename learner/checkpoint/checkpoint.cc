#include "learner/checkpoint/checkpoint.h"

#include <fcntl.h>
#include <torch/serialize/archive.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <sstream>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "learner/checkpoint/archive_integrity.h"
#include "learner/checkpoint/archive_io.h"

namespace vantage {
namespace {

constexpr char kPrefix[] = "checkpoint-";
constexpr char kSuffix[] = ".pt";

absl::Status ErrnoError(const std::string& what, const std::string& path) {
  return absl::InternalError(
      absl::StrCat(what, " ", path, ": ", std::strerror(errno)));
}

// Writes `bytes` to `path` and flushes them to the disk.
absl::Status WriteDurably(const std::string& path, const std::string& bytes) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (fd < 0) return ErrnoError("cannot create", path);
  size_t written = 0;
  while (written < bytes.size()) {
    const ssize_t n =
        ::write(fd, bytes.data() + written, bytes.size() - written);
    if (n < 0) {
      if (errno == EINTR) continue;
      const absl::Status status = ErrnoError("cannot write", path);
      ::close(fd);
      return status;
    }
    written += static_cast<size_t>(n);
  }
  if (::fsync(fd) != 0) {
    const absl::Status status = ErrnoError("cannot flush", path);
    ::close(fd);
    return status;
  }
  if (::close(fd) != 0) return ErrnoError("cannot close", path);
  return absl::OkStatus();
}

absl::StatusOr<torch::serialize::InputArchive> OpenArchive(
    const std::string& path) {
  if (!std::filesystem::is_regular_file(path)) {
    return absl::NotFoundError(absl::StrCat("no checkpoint file ", path));
  }
  if (absl::Status status = VerifyArchiveIntegrity(path); !status.ok()) {
    return status;
  }
  torch::serialize::InputArchive archive;
  if (absl::Status status = CatchTorchErrors(
          absl::StrCat("checkpoint ", path, " is not a readable checkpoint"),
          [&] { archive.load_from(path); });
      !status.ok()) {
    return status;
  }
  return archive;
}

absl::Status InFile(const std::string& path, const absl::Status& status) {
  if (status.ok()) return status;
  return absl::Status(
      status.code(), absl::StrCat("checkpoint ", path, ": ", status.message()));
}

}  // namespace

std::string CheckpointPath(const std::string& directory, int64_t version) {
  return absl::StrFormat("%s/%s%08d%s", directory, kPrefix, version, kSuffix);
}

absl::Status WriteCheckpoint(const std::string& path,
                             const LearnerCore& learner,
                             const CheckpointExtras& extras) {
  torch::serialize::OutputArchive archive;
  learner.Save(archive);
  std::vector<std::string> names;
  for (const auto& [name, bytes] : extras) {
    names.push_back(name);
    WriteBytes(archive, "extra." + name, bytes);
  }
  WriteBytes(archive, "extras", absl::StrJoin(names, "\n"));
  std::ostringstream stream;
  archive.save_to(stream);
  const std::string temporary = path + ".tmp";
  if (absl::Status status = WriteDurably(temporary, stream.str());
      !status.ok()) {
    std::remove(temporary.c_str());
    return status;
  }
  if (std::rename(temporary.c_str(), path.c_str()) != 0) {
    const absl::Status status = ErrnoError("cannot rename into", path);
    std::remove(temporary.c_str());
    return status;
  }
  // Make the rename itself durable.
  const std::string directory =
      std::filesystem::path(path).parent_path().string();
  const int fd = ::open(directory.empty() ? "." : directory.c_str(),
                        O_RDONLY | O_DIRECTORY);
  if (fd >= 0) {
    ::fsync(fd);
    ::close(fd);
  }
  return absl::OkStatus();
}

absl::StatusOr<CheckpointExtras> ReadCheckpointExtras(const std::string& path) {
  absl::StatusOr<torch::serialize::InputArchive> archive = OpenArchive(path);
  if (!archive.ok()) return archive.status();
  absl::StatusOr<std::string> names = ReadBytes(*archive, "extras");
  if (!names.ok()) return InFile(path, names.status());
  CheckpointExtras extras;
  if (names->empty()) return extras;
  for (absl::string_view name : absl::StrSplit(*names, '\n')) {
    absl::StatusOr<std::string> bytes =
        ReadBytes(*archive, absl::StrCat("extra.", name));
    if (!bytes.ok()) return InFile(path, bytes.status());
    extras[std::string(name)] = *std::move(bytes);
  }
  return extras;
}

absl::StatusOr<std::unique_ptr<LearnerCore>> ReadCheckpoint(
    const std::string& path, const LearnerConfig& config,
    std::shared_ptr<ReplicaGroup> replicas) {
  absl::StatusOr<torch::serialize::InputArchive> archive = OpenArchive(path);
  if (!archive.ok()) return archive.status();
  absl::StatusOr<std::unique_ptr<LearnerCore>> learner =
      LearnerCore::Load(config, *archive, std::move(replicas));
  if (!learner.ok()) return InFile(path, learner.status());
  return learner;
}

std::vector<std::string> ListCheckpoints(const std::string& directory) {
  std::vector<std::string> paths;
  std::error_code error;
  for (const auto& entry :
       std::filesystem::directory_iterator(directory, error)) {
    const std::string name = entry.path().filename().string();
    const size_t prefix = std::strlen(kPrefix);
    const size_t suffix = std::strlen(kSuffix);
    if (name.size() > prefix + suffix && name.rfind(kPrefix, 0) == 0 &&
        name.compare(name.size() - suffix, suffix, kSuffix) == 0 &&
        std::all_of(name.begin() + prefix, name.end() - suffix, ::isdigit)) {
      paths.push_back(entry.path().string());
    }
  }
  // Zero-padded versions sort by name; longer names are later versions.
  std::sort(paths.begin(), paths.end(),
            [](const std::string& a, const std::string& b) {
              return a.size() != b.size() ? a.size() < b.size() : a < b;
            });
  return paths;
}

absl::Status PruneCheckpoints(const std::string& directory, int keep) {
  const std::vector<std::string> paths = ListCheckpoints(directory);
  for (size_t i = 0; i + keep < paths.size(); ++i) {
    std::error_code error;
    std::filesystem::remove(paths[i], error);
    if (error) {
      return absl::InternalError(
          absl::StrCat("cannot delete ", paths[i], ": ", error.message()));
    }
  }
  return absl::OkStatus();
}

}  // namespace vantage
