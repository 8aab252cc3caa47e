#ifndef VANTAGE_COMMON_UTIL_STATE_BYTES_H_
#define VANTAGE_COMMON_UTIL_STATE_BYTES_H_

// The byte format of saved object states (environments, vectors of them,
// actor cores): opaque blobs that a checkpoint stores and hands back.
//
//   magic "VNTGSTAT" | u32 byte-order mark | u64 total size |
//   kind (field) | version (field) | fields ... | u64 checksum
//
// A field is a u64 byte count followed by that many bytes, so a reader
// checks every field's size, not just the blob's. Numbers are stored in the
// writer's byte order (the byte-order mark refuses the other one): the
// blobs embed raw MuJoCo and LibTorch state, which is not portable either.
// The checksum (not cryptographic) covers everything before it and catches
// corruption that keeps the size.

#include <cstddef>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/string_view.h"
#include "absl/types/span.h"

namespace vantage {

// The checksum the blobs carry, also for fingerprinting what a state
// depends on (not cryptographic).
uint64_t Fingerprint(absl::string_view bytes);

class StateWriter {
 public:
  // `kind` names the saving class ("mujoco_env"); readers refuse any other
  // kind or version.
  StateWriter(absl::string_view kind, uint32_t version);

  void PutU64(uint64_t value);
  void PutI64(int64_t value);
  void PutDouble(double value);
  void PutBool(bool value);
  void PutBytes(absl::string_view bytes);
  void PutDoubles(absl::Span<const double> values);
  void PutI64s(absl::Span<const int64_t> values);
  // `bytes` with the runs of zero 8-byte words squeezed out: for large
  // buffers that are mostly unused (MuJoCo's is megabytes, mostly
  // constraint rows no step has filled).
  void PutPacked(absl::string_view bytes);
  // The standard textual form, the only portable way out of the engine.
  void PutEngine(const std::mt19937_64& engine);

  // The finished blob; the writer is spent.
  std::string Finish() &&;

 private:
  void PutRaw(const void* data, size_t size);

  std::string out_;
};

// Reads fields in the order they were written. The first error sticks:
// later reads return zero values and change nothing, so callers parse
// everything, check status() (or Finish()) once, and only then apply what
// they read. Every error is InvalidArgument and starts with `context`.
class StateReader {
 public:
  // Checks the magic, byte order, size, checksum, kind and version.
  StateReader(absl::string_view blob, absl::string_view kind, uint32_t version,
              std::string context);

  uint64_t GetU64(absl::string_view field);
  int64_t GetI64(absl::string_view field);
  double GetDouble(absl::string_view field);
  bool GetBool(absl::string_view field);
  // A view into the blob passed to the constructor.
  absl::string_view GetBytes(absl::string_view field);
  // `count` values exactly.
  std::vector<double> GetDoubles(absl::string_view field, size_t count);
  std::vector<int64_t> GetI64s(absl::string_view field, size_t count);
  // What PutPacked was given, which must be `size` bytes.
  std::string GetPacked(absl::string_view field, size_t size);
  std::mt19937_64 GetEngine(absl::string_view field);

  // Records an error unless the saved `value` equals this object's.
  void ExpectEqual(absl::string_view field, int64_t value, int64_t expected);
  void ExpectEqual(absl::string_view field, absl::string_view value,
                   absl::string_view expected);
  // Records `message` unless `condition` holds (or an error came first).
  void Check(bool condition, absl::string_view message);

  // True once every field has been read.
  bool AtEnd() const { return status_.ok() && pos_ == end_; }
  const absl::Status& status() const { return status_; }
  // status(), or an error if fields are left unread.
  absl::Status Finish();

 private:
  // The next field's bytes if it holds exactly `size` bytes (any size if
  // `size` is npos); empty after an error.
  absl::string_view Field(absl::string_view field,
                          size_t size = absl::string_view::npos);
  void Fail(absl::string_view message);

  absl::string_view blob_;
  std::string context_;
  size_t pos_ = 0;
  size_t end_ = 0;  // where the checksum starts
  absl::Status status_;
};

}  // namespace vantage

#endif  // VANTAGE_COMMON_UTIL_STATE_BYTES_H_
