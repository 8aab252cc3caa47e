#include "learner/checkpoint/archive_integrity.h"

#include <minizip/unzip.h>

#include <array>
#include <memory>

#include "absl/strings/str_cat.h"

namespace vantage {
namespace {

absl::Status Damaged(const std::string& path, absl::string_view why) {
  return absl::InvalidArgumentError(
      absl::StrCat("checkpoint ", path, " is damaged: ", why));
}

}  // namespace

absl::Status VerifyArchiveIntegrity(const std::string& path) {
  std::unique_ptr<void, int (*)(unzFile)> zip(unzOpen64(path.c_str()),
                                              &unzClose);
  if (zip == nullptr) {
    return Damaged(path, "not a zip archive (no readable central directory)");
  }
  std::array<char, 1 << 16> buffer;
  int64_t entries = 0;
  int next = unzGoToFirstFile(zip.get());
  for (; next == UNZ_OK; next = unzGoToNextFile(zip.get()), ++entries) {
    std::array<char, 1024> name{};
    unz_file_info64 info;
    if (unzGetCurrentFileInfo64(zip.get(), &info, name.data(), name.size() - 1,
                                nullptr, 0, nullptr, 0) != UNZ_OK) {
      return Damaged(path, absl::StrCat("the directory record of entry ",
                                        entries, " is unreadable"));
    }
    const std::string entry = absl::StrCat("entry '", name.data(), "'");
    // Opening checks the entry's local header against its directory record.
    if (unzOpenCurrentFile(zip.get()) != UNZ_OK) {
      return Damaged(path,
                     absl::StrCat(entry, " has no matching local header"));
    }
    int read = 0;
    do {
      read = unzReadCurrentFile(zip.get(), buffer.data(), buffer.size());
    } while (read > 0);
    // Closing an entry read to its end compares the CRC-32s.
    const int closed = unzCloseCurrentFile(zip.get());
    if (read < 0) {
      return Damaged(path, absl::StrCat(entry, " cannot be read in full"));
    }
    if (closed == UNZ_CRCERROR) {
      return Damaged(path, absl::StrCat(entry, " fails its CRC-32 check"));
    }
    if (closed != UNZ_OK) {
      return Damaged(path, absl::StrCat(entry, " cannot be read in full"));
    }
  }
  if (next != UNZ_END_OF_LIST_OF_FILE) {
    return Damaged(path, absl::StrCat("the directory is unreadable after ",
                                      entries, " entries"));
  }
  if (entries == 0) return Damaged(path, "the archive holds no entries");
  return absl::OkStatus();
}

}  // namespace vantage
