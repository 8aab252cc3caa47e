// Checkpoint files as a resuming learner reads them: the bytes are written
// to a file and read by ReadFuzzCheckpoint (ReadCheckpointExtras, then
// ReadCheckpoint with a small fixed learner); a learner that loads must
// pass CheckLoadedLearner (finite weights, one update).
//
// The reader verifies every zip entry's CRC-32 (VerifyArchiveIntegrity)
// before LibTorch sees the file, because LibTorch checks none and its
// TorchScript parser crashes on some corrupt code/ sources (SEGV in
// ScriptTypeParser::parseClassConstant) while its unpickler allocates
// whatever a corrupt pickle names. So mutations that break an entry reach
// minizip's parsing and the verifier; those that keep every CRC (the zip
// structure around the entries: directory, offsets, extra fields) reach
// LibTorch. checkpoint_entries_fuzzer covers what a pickle decides (each
// entry's dtype, shape and values) through LibTorch's own writer.

#include <ATen/ATen.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <memory>
#include <string>

#include "absl/status/statusor.h"
#include "tests/fuzz/fuzz_fixtures.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  at::set_num_threads(1);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace vantage;
  static const std::string path = FuzzTempPath("checkpoint_fuzzer.pt");
  {
    std::ofstream file(path, std::ios::binary | std::ios::trunc);
    file.write(reinterpret_cast<const char*>(data),
               static_cast<std::streamsize>(size));
    if (!file) return 0;
  }
  absl::StatusOr<std::unique_ptr<LearnerCore>> learner =
      ReadFuzzCheckpoint(path);
  if (learner.ok()) CheckLoadedLearner(**learner);
  std::remove(path.c_str());
  return 0;
}
