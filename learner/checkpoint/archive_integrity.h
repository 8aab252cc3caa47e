#ifndef VANTAGE_LEARNER_CHECKPOINT_ARCHIVE_INTEGRITY_H_
#define VANTAGE_LEARNER_CHECKPOINT_ARCHIVE_INTEGRITY_H_

// Checkpoints are zip archives (LibTorch's format). LibTorch's reader checks
// none of an archive's CRC-32s, and what it then parses from corrupt bytes
// can crash the process (its TorchScript parser) or allocate whatever a
// corrupt pickle names, neither of which an exception reports. So every
// checkpoint is verified with minizip before LibTorch opens it. This catches
// corruption (a damaged disk, a truncated or partial copy), not forgery: a
// checkpoint is the run's own file, as trusted as its run directory.

#include <string>

#include "absl/status/status.h"

namespace vantage {

// OK when `path` is a zip archive with at least one entry whose every entry
// reads back in full with the CRC-32 its directory records; otherwise
// InvalidArgument naming the first entry that does not.
absl::Status VerifyArchiveIntegrity(const std::string& path);

}  // namespace vantage

#endif  // VANTAGE_LEARNER_CHECKPOINT_ARCHIVE_INTEGRITY_H_
