#include "common/util/state_bytes.h"

#include <cstring>
#include <limits>
#include <locale>
#include <sstream>
#include <utility>

#include "absl/strings/str_cat.h"

namespace vantage {
namespace {

constexpr char kMagic[8] = {'V', 'N', 'T', 'G', 'S', 'T', 'A', 'T'};
constexpr uint32_t kByteOrderMark = 0x01020304;
constexpr size_t kTotalSizeOffset = sizeof(kMagic) + sizeof(uint32_t);
constexpr size_t kHeaderSize = kTotalSizeOffset + sizeof(uint64_t);
constexpr size_t kChecksumSize = sizeof(uint64_t);

template <typename T>
T Load(const char* data) {
  T value;
  std::memcpy(&value, data, sizeof(T));
  return value;
}

// Word-at-a-time multiply-xorshift: fast enough to run over every MuJoCo
// buffer at each nesting level, and any change of a byte changes it with
// overwhelming probability.
}  // namespace

uint64_t Fingerprint(absl::string_view bytes) {
  constexpr uint64_t kMultiplier = 0x9E3779B97F4A7C15ULL;
  uint64_t hash = 0xCBF29CE484222325ULL ^ bytes.size();
  size_t i = 0;
  for (; i + 8 <= bytes.size(); i += 8) {
    hash = (hash ^ Load<uint64_t>(bytes.data() + i)) * kMultiplier;
    hash ^= hash >> 29;
  }
  for (; i < bytes.size(); ++i) {
    hash = (hash ^ static_cast<unsigned char>(bytes[i])) * kMultiplier;
    hash ^= hash >> 29;
  }
  return hash;
}

StateWriter::StateWriter(absl::string_view kind, uint32_t version) {
  PutRaw(kMagic, sizeof(kMagic));
  PutRaw(&kByteOrderMark, sizeof(kByteOrderMark));
  const uint64_t size_placeholder = 0;
  PutRaw(&size_placeholder, sizeof(size_placeholder));
  PutBytes(kind);
  PutU64(version);
}

void StateWriter::PutRaw(const void* data, size_t size) {
  out_.append(static_cast<const char*>(data), size);
}

void StateWriter::PutBytes(absl::string_view bytes) {
  const uint64_t size = bytes.size();
  PutRaw(&size, sizeof(size));
  PutRaw(bytes.data(), bytes.size());
}

void StateWriter::PutU64(uint64_t value) {
  PutBytes(
      absl::string_view(reinterpret_cast<const char*>(&value), sizeof(value)));
}

void StateWriter::PutI64(int64_t value) {
  PutU64(static_cast<uint64_t>(value));
}

void StateWriter::PutDouble(double value) {
  PutBytes(
      absl::string_view(reinterpret_cast<const char*>(&value), sizeof(value)));
}

void StateWriter::PutBool(bool value) {
  const char byte = value ? 1 : 0;
  PutBytes(absl::string_view(&byte, 1));
}

void StateWriter::PutDoubles(absl::Span<const double> values) {
  PutBytes(absl::string_view(reinterpret_cast<const char*>(values.data()),
                             values.size() * sizeof(double)));
}

void StateWriter::PutI64s(absl::Span<const int64_t> values) {
  PutBytes(absl::string_view(reinterpret_cast<const char*>(values.data()),
                             values.size() * sizeof(int64_t)));
}

void StateWriter::PutPacked(absl::string_view bytes) {
  // u64 size, then (u32 zero words, u32 literal words, the literal words)
  // groups up to the last whole word, then the remaining bytes as they are.
  constexpr size_t kMaxRun = std::numeric_limits<uint32_t>::max();
  const size_t words = bytes.size() / 8;
  const auto zero = [&](size_t i) {
    return Load<uint64_t>(bytes.data() + 8 * i) == 0;
  };
  std::string packed;
  const auto append = [&packed](const auto& value) {
    packed.append(reinterpret_cast<const char*>(&value), sizeof(value));
  };
  append(static_cast<uint64_t>(bytes.size()));
  size_t i = 0;
  while (i < words) {
    uint32_t zeros = 0;
    while (i + zeros < words && zeros < kMaxRun && zero(i + zeros)) ++zeros;
    i += zeros;
    uint32_t literals = 0;
    while (i + literals < words && literals < kMaxRun && !zero(i + literals)) {
      ++literals;
    }
    append(zeros);
    append(literals);
    packed.append(bytes.data() + 8 * i, 8 * size_t{literals});
    i += literals;
  }
  packed.append(bytes.data() + 8 * words, bytes.size() - 8 * words);
  PutBytes(packed);
}

void StateWriter::PutEngine(const std::mt19937_64& engine) {
  std::ostringstream text;
  text.imbue(std::locale::classic());
  text << engine;
  PutBytes(text.str());
}

std::string StateWriter::Finish() && {
  const uint64_t total = out_.size() + kChecksumSize;
  std::memcpy(out_.data() + kTotalSizeOffset, &total, sizeof(total));
  const uint64_t checksum = Fingerprint(out_);
  PutRaw(&checksum, sizeof(checksum));
  return std::move(out_);
}

StateReader::StateReader(absl::string_view blob, absl::string_view kind,
                         uint32_t version, std::string context)
    : blob_(blob), context_(std::move(context)) {
  const absl::string_view magic(kMagic, sizeof(kMagic));
  if (blob.substr(0, magic.size()) != magic.substr(0, blob.size())) {
    Fail("not a saved state (wrong magic bytes)");
    return;
  }
  if (blob.size() < kHeaderSize + kChecksumSize) {
    Fail(absl::StrCat("truncated: ", blob.size(),
                      " bytes, fewer than any saved state has"));
    return;
  }
  const uint32_t mark = Load<uint32_t>(blob.data() + sizeof(kMagic));
  if (mark != kByteOrderMark) {
    Fail(mark == 0x04030201 ? "written on a machine of the other byte order"
                            : "not a saved state (bad byte-order mark)");
    return;
  }
  const uint64_t total = Load<uint64_t>(blob.data() + kTotalSizeOffset);
  if (total > blob.size()) {
    Fail(absl::StrCat("truncated: ", blob.size(), " of its ", total, " bytes"));
    return;
  }
  if (total < blob.size()) {
    Fail(absl::StrCat(blob.size() - total, " stray bytes after its ", total,
                      " bytes"));
    return;
  }
  end_ = blob.size() - kChecksumSize;
  if (Fingerprint(blob.substr(0, end_)) != Load<uint64_t>(blob.data() + end_)) {
    Fail("checksum mismatch: the state is corrupted");
    return;
  }
  pos_ = kHeaderSize;
  const absl::string_view saved_kind = GetBytes("kind");
  Check(saved_kind == kind,
        absl::StrCat("holds a '", saved_kind, "' state, not a '", kind, "'"));
  const uint64_t saved_version = GetU64("version");
  Check(saved_version == version,
        absl::StrCat("is format version ", saved_version, " of '", kind,
                     "'; this build reads version ", version));
}

void StateReader::Fail(absl::string_view message) {
  if (!status_.ok()) return;
  status_ = absl::InvalidArgumentError(absl::StrCat(context_, ": ", message));
}

void StateReader::Check(bool condition, absl::string_view message) {
  if (!condition) Fail(message);
}

absl::string_view StateReader::Field(absl::string_view field, size_t size) {
  if (!status_.ok()) return {};
  if (end_ - pos_ < sizeof(uint64_t)) {
    Fail(absl::StrCat("ends before field '", field, "'"));
    return {};
  }
  const uint64_t length = Load<uint64_t>(blob_.data() + pos_);
  const size_t left = end_ - pos_ - sizeof(uint64_t);
  if (length > left) {
    Fail(absl::StrCat("field '", field, "' claims ", length, " bytes but only ",
                      left, " are left"));
    return {};
  }
  if (size != absl::string_view::npos && length != size) {
    Fail(absl::StrCat("field '", field, "' holds ", length, " bytes, expected ",
                      size));
    return {};
  }
  const absl::string_view bytes = blob_.substr(pos_ + sizeof(uint64_t), length);
  pos_ += sizeof(uint64_t) + length;
  return bytes;
}

uint64_t StateReader::GetU64(absl::string_view field) {
  const absl::string_view bytes = Field(field, sizeof(uint64_t));
  return bytes.empty() ? 0 : Load<uint64_t>(bytes.data());
}

int64_t StateReader::GetI64(absl::string_view field) {
  return static_cast<int64_t>(GetU64(field));
}

double StateReader::GetDouble(absl::string_view field) {
  const absl::string_view bytes = Field(field, sizeof(double));
  return bytes.empty() ? 0.0 : Load<double>(bytes.data());
}

bool StateReader::GetBool(absl::string_view field) {
  const absl::string_view bytes = Field(field, 1);
  if (bytes.empty()) return false;
  Check(bytes[0] == 0 || bytes[0] == 1,
        absl::StrCat("field '", field, "' is not a bool (byte ",
                     static_cast<int>(bytes[0]), ")"));
  return bytes[0] == 1;
}

absl::string_view StateReader::GetBytes(absl::string_view field) {
  return Field(field);
}

std::vector<double> StateReader::GetDoubles(absl::string_view field,
                                            size_t count) {
  const absl::string_view bytes = Field(field, count * sizeof(double));
  if (!status_.ok()) return std::vector<double>(count, 0.0);
  std::vector<double> values(count);
  if (count > 0) std::memcpy(values.data(), bytes.data(), bytes.size());
  return values;
}

std::vector<int64_t> StateReader::GetI64s(absl::string_view field,
                                          size_t count) {
  const absl::string_view bytes = Field(field, count * sizeof(int64_t));
  if (!status_.ok()) return std::vector<int64_t>(count, 0);
  std::vector<int64_t> values(count);
  if (count > 0) std::memcpy(values.data(), bytes.data(), bytes.size());
  return values;
}

std::string StateReader::GetPacked(absl::string_view field, size_t size) {
  const absl::string_view packed = Field(field);
  if (!status_.ok()) return std::string();
  const auto bad = [&](absl::string_view why) {
    Fail(absl::StrCat("field '", field, "' is not a packed buffer: ", why));
    return std::string();
  };
  if (packed.size() < sizeof(uint64_t)) return bad("no size");
  const uint64_t saved_size = Load<uint64_t>(packed.data());
  if (saved_size != size) {
    return bad(
        absl::StrCat("it unpacks to ", saved_size, " bytes, expected ", size));
  }
  const size_t words = size / 8;
  std::string bytes(size, '\0');
  size_t pos = sizeof(uint64_t);
  size_t i = 0;
  while (i < words) {
    if (packed.size() - pos < 2 * sizeof(uint32_t)) return bad("truncated");
    const uint32_t zeros = Load<uint32_t>(packed.data() + pos);
    const uint32_t literals = Load<uint32_t>(packed.data() + pos + 4);
    pos += 2 * sizeof(uint32_t);
    if (size_t{zeros} + literals == 0 || size_t{zeros} + literals > words - i) {
      return bad("a run does not fit");
    }
    i += zeros;
    if (packed.size() - pos < 8 * size_t{literals}) return bad("truncated");
    std::memcpy(bytes.data() + 8 * i, packed.data() + pos,
                8 * size_t{literals});
    pos += 8 * size_t{literals};
    i += literals;
  }
  if (packed.size() - pos != size - 8 * words) {
    return bad("wrong number of trailing bytes");
  }
  std::memcpy(bytes.data() + 8 * words, packed.data() + pos, size - 8 * words);
  return bytes;
}

std::mt19937_64 StateReader::GetEngine(absl::string_view field) {
  std::mt19937_64 engine;
  const absl::string_view bytes = Field(field);
  if (!status_.ok()) return engine;
  std::istringstream text{std::string(bytes)};
  text.imbue(std::locale::classic());
  text >> engine;
  const bool parsed = !text.fail();
  std::string rest;
  if (parsed) text >> rest;
  Check(parsed && rest.empty(),
        absl::StrCat("field '", field, "' is not a mt19937_64 state"));
  return engine;
}

void StateReader::ExpectEqual(absl::string_view field, int64_t value,
                              int64_t expected) {
  Check(value == expected,
        absl::StrCat(field, " is ", value, " in the state but ", expected,
                     " here"));
}

void StateReader::ExpectEqual(absl::string_view field, absl::string_view value,
                              absl::string_view expected) {
  Check(value == expected,
        absl::StrCat(field, " is '", value, "' in the state but '", expected,
                     "' here"));
}

absl::Status StateReader::Finish() {
  Check(pos_ == end_,
        absl::StrCat(end_ - pos_, " bytes of unread fields at the end"));
  return status_;
}

}  // namespace vantage
