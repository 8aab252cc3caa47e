// Checkpoint files as a resuming learner reads them: the bytes are written
// to a file and read by ReadFuzzCheckpoint (ReadCheckpointExtras, then
// ReadCheckpoint with a small fixed learner); a learner that loads must
// pass CheckLoadedLearner (finite weights, one update).
//
// A checkpoint is a zip archive, and LibTorch 1.13 checks none of its
// CRC-32s: it parses whatever bytes an entry holds. Its own parsers do not
// survive that. Its TorchScript parser, which compiles the sources under
// code/ that every archive carries, crashes on some corrupt sources (SEGV
// in ScriptTypeParser::parseClassConstant), and its unpickler allocates
// whatever sizes a corrupt pickle names (tens of GB), which our code
// cannot catch. So this fuzzer skips inputs whose pickles (*.pkl) or
// TorchScript sources (code/) do not match their CRC-32s, which is what
// they would fail if LibTorch checked them; it covers the zip structure,
// the tensor payloads and the plain entries, and whatever LibTorch throws
// on those. checkpoint_entries_fuzzer covers what a pickle decides (each
// entry's dtype, shape and values) through LibTorch's own writer.

#include <ATen/ATen.h>
#include <zlib.h>

#include <cctype>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/string_view.h"
#include "tests/fuzz/fuzz_fixtures.h"

namespace vantage {
namespace {

// Little-endian, as every zip field is; zero past the end of the input.
uint64_t Read(const uint8_t* data, size_t size, uint64_t at, int bytes) {
  uint64_t value = 0;
  for (int i = bytes - 1; i >= 0; --i) {
    value = (value << 8) | (at + i < size ? data[at + i] : 0);
  }
  return value;
}

// LibTorch finds entries by case-insensitive name (miniz's default).
bool Parsed(absl::string_view name) {
  const std::string lower = absl::AsciiStrToLower(name);
  return absl::StrContains(lower, "/code/") || absl::EndsWith(lower, "pkl");
}

bool CrcMatches(const uint8_t* data, size_t size, uint64_t start,
                uint64_t stored, uint64_t unpacked, int method, uint32_t crc) {
  if (start > size || stored > size - start) return false;
  const uint8_t* bytes = data + start;
  if (method == 0) {
    return crc32(0, bytes, static_cast<uInt>(stored)) == crc;
  }
  if (method != 8 || unpacked > (1 << 20)) return false;
  std::vector<uint8_t> out(unpacked);
  z_stream stream{};
  if (inflateInit2(&stream, -MAX_WBITS) != Z_OK) return false;
  stream.next_in = const_cast<uint8_t*>(bytes);
  stream.avail_in = static_cast<uInt>(stored);
  stream.next_out = out.data();
  stream.avail_out = static_cast<uInt>(out.size());
  const int result = inflate(&stream, Z_FINISH);
  const bool complete = result == Z_STREAM_END && stream.total_out == unpacked;
  inflateEnd(&stream);
  return complete && crc32(0, out.data(), static_cast<uInt>(out.size())) == crc;
}

// Reads the central directory the way miniz does (the end record, or the
// zip64 one its locator points to) and checks every parsed entry's CRC-32.
// Anything this cannot follow counts as not intact.
bool ParsedEntriesIntact(const uint8_t* data, size_t size) {
  constexpr uint64_t kEndSize = 22;
  if (size < kEndSize) return true;  // no archive: LibTorch parses nothing
  uint64_t end = size - kEndSize;
  while (Read(data, size, end, 4) != 0x06054b50u) {
    if (end == 0) return true;
    --end;
  }
  uint64_t entries = Read(data, size, end + 10, 2);
  uint64_t directory = Read(data, size, end + 16, 4);
  uint64_t directory_size = Read(data, size, end + 12, 4);
  if (end >= 20 && Read(data, size, end - 20, 4) == 0x07064b50u) {
    const uint64_t zip64 = Read(data, size, end - 20 + 8, 8);
    if (zip64 > size || size - zip64 < 56) return false;
    if (Read(data, size, zip64, 4) == 0x06064b50u) {
      entries = Read(data, size, zip64 + 32, 8);
      directory_size = Read(data, size, zip64 + 40, 8);
      directory = Read(data, size, zip64 + 48, 8);
    }
  }
  if (directory > size || directory_size > size - directory) return false;
  uint64_t at = directory;
  const uint64_t directory_end = directory + directory_size;
  for (uint64_t i = 0; i < entries && at < directory_end; ++i) {
    if (directory_end - at < 46 || Read(data, size, at, 4) != 0x02014b50u) {
      return false;
    }
    const uint64_t name_size = Read(data, size, at + 28, 2);
    const uint64_t next = at + 46 + name_size + Read(data, size, at + 30, 2) +
                          Read(data, size, at + 32, 2);
    if (next > directory_end) return false;
    const absl::string_view name(reinterpret_cast<const char*>(data + at + 46),
                                 name_size);
    if (Parsed(name)) {
      const uint64_t stored = Read(data, size, at + 20, 4);
      const uint64_t unpacked = Read(data, size, at + 24, 4);
      const uint64_t local = Read(data, size, at + 42, 4);
      // Sizes or offsets in a zip64 extra field: not followed here.
      if (stored == 0xFFFFFFFFu || unpacked == 0xFFFFFFFFu ||
          local == 0xFFFFFFFFu || local > size || size - local < 30 ||
          Read(data, size, local, 4) != 0x04034b50u) {
        return false;
      }
      const uint64_t start = local + 30 + Read(data, size, local + 26, 2) +
                             Read(data, size, local + 28, 2);
      if (!CrcMatches(data, size, start, stored, unpacked,
                      static_cast<int>(Read(data, size, at + 10, 2)),
                      static_cast<uint32_t>(Read(data, size, at + 16, 4)))) {
        return false;
      }
    }
    at = next;
  }
  return true;
}

}  // namespace
}  // namespace vantage

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  at::set_num_threads(1);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace vantage;
  if (!ParsedEntriesIntact(data, size)) return 0;
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
