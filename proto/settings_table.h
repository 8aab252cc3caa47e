#ifndef VANTAGE_PROTO_SETTINGS_TABLE_H_
#define VANTAGE_PROTO_SETTINGS_TABLE_H_

// A section of the run config (proto/run_config.proto) and the typed config
// of the component it fills, each setting declared once: the config member,
// the field of the section's message, and the range the config's Validate()
// holds it to. Reading the message over the config's defaults, writing the
// resolved config back and checking the ranges all walk the one table, by
// the message's reflection. Only the sources that define a component's
// table include this (it brings protobuf).

#include <google/protobuf/descriptor.h>
#include <google/protobuf/message.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/string_view.h"

namespace vantage {

// One end of a setting's range.
struct SettingBound {
  double value = 0;
  bool inclusive = true;
};

inline SettingBound AtLeast(double value) { return {value, true}; }
inline SettingBound Above(double value) { return {value, false}; }
inline SettingBound Below(double value) { return {value, false}; }
inline SettingBound AtMost(double value) { return {value, true}; }

// A rule that a setting breaks, named by its flag, as the tables' own
// messages name them ("--envs must be in [1, 4096]"): for the rules a table
// cannot state (those across settings).
inline absl::Status FlagError(absl::string_view flag, absl::string_view rule) {
  return absl::InvalidArgumentError(absl::StrCat("--", flag, " ", rule));
}

// How a table's messages name a setting: by its section and field, as an
// algorithm's settings are named ("ppo.clip must be in (0, 1)"), or by the
// field's flag, as the run's own sections are ("--steps must be >= 1").
enum class SettingNames { kSectionField, kFlag };

template <typename Config, typename Settings>
class SettingsTable {
 public:
  using Member =
      std::variant<int Config::*, int64_t Config::*, uint64_t Config::*,
                   double Config::*, bool Config::*, std::string Config::*,
                   std::vector<int64_t> Config::*>;
  struct Row {
    Row(const char* field, Member member,
        std::optional<SettingBound> low = std::nullopt,
        std::optional<SettingBound> high = std::nullopt, const char* note = "")
        : field(field), member(member), low(low), high(high), note(note) {}
    const char* field;  // in the settings message
    Member member;
    std::optional<SettingBound> low;
    std::optional<SettingBound> high;
    const char* note;  // added to the range's message ("(0: automatic)")
  };

  // `section` names the settings in messages ("ppo": "ppo.clip must be
  // ..."), or `names` says to name them by flag. A row whose field Settings
  // lacks, or a range on a member that is not a number (a bool, a string,
  // a list), is a programming error: it stops the program at the first
  // use of the table.
  SettingsTable(const char* section, std::vector<Row> rows,
                SettingNames names = SettingNames::kSectionField)
      : section_(section), names_(names), rows_(std::move(rows)) {
    for (const Row& row : rows_) {
      if (Settings::descriptor()->FindFieldByName(row.field) == nullptr) {
        Abort(section, row, "settings have no such field");
      }
      const bool number =
          std::visit([](auto member) { return IsNumber(member); }, row.member);
      if (!number && (row.low.has_value() || row.high.has_value())) {
        Abort(section, row, "is not a number and can have no range");
      }
    }
  }

  // Each member whose field `settings` holds (a list: with an element),
  // over the config's defaults.
  void Read(const Settings& settings, Config& config) const {
    const auto* reflection = settings.GetReflection();
    for (const Row& row : rows_) {
      const google::protobuf::FieldDescriptor* field = Field(settings, row);
      const bool given = field->is_repeated()
                             ? reflection->FieldSize(settings, field) > 0
                             : reflection->HasField(settings, field);
      if (!given) continue;
      std::visit([&](auto member) { Get(settings, *field, config.*member); },
                 row.member);
    }
  }

  // The config `defaults` with what `settings` holds, checked, and written
  // back whole into `settings` (every field then says what the run uses).
  absl::StatusOr<Config> Resolve(Config defaults, Settings& settings) const {
    Read(settings, defaults);
    if (absl::Status status = Validate(defaults); !status.ok()) return status;
    Write(defaults, settings);
    return defaults;
  }

  // Every member into its field.
  void Write(const Config& config, Settings& settings) const {
    for (const Row& row : rows_) {
      const google::protobuf::FieldDescriptor* field = Field(settings, row);
      std::visit([&](auto member) { Set(config.*member, *field, settings); },
                 row.member);
    }
  }

  // The first member outside its range, in the table's order
  // ("ppo.clip must be in (0, 1)").
  absl::Status Validate(const Config& config) const {
    for (const Row& row : rows_) {
      if (!row.low.has_value() && !row.high.has_value()) continue;
      const double value = std::visit(
          [&](auto member) -> double {
            using Value = std::decay_t<decltype(config.*member)>;
            // The constructor allows ranges on numbers only.
            if constexpr (std::is_arithmetic_v<Value>) {
              return static_cast<double>(config.*member);
            }
            return 0.0;
          },
          row.member);
      if (InRange(value, row)) continue;
      const std::string name = names_ == SettingNames::kFlag
                                   ? absl::StrCat("--", row.field)
                                   : absl::StrCat(section_, ".", row.field);
      return absl::InvalidArgumentError(
          absl::StrCat(name, " must be ", Range(row),
                       *row.note == '\0' ? "" : " ", row.note));
    }
    return absl::OkStatus();
  }

 private:
  static const google::protobuf::FieldDescriptor* Field(
      const google::protobuf::Message& settings, const Row& row) {
    return settings.GetDescriptor()->FindFieldByName(row.field);
  }

  template <typename Value>
  static bool IsNumber(Value Config::*) {
    return std::is_arithmetic_v<Value> && !std::is_same_v<Value, bool>;
  }

  static void Get(const google::protobuf::Message& m,
                  const google::protobuf::FieldDescriptor& f, int& out) {
    out = m.GetReflection()->GetInt32(m, &f);
  }
  static void Get(const google::protobuf::Message& m,
                  const google::protobuf::FieldDescriptor& f, int64_t& out) {
    out = m.GetReflection()->GetInt64(m, &f);
  }
  static void Get(const google::protobuf::Message& m,
                  const google::protobuf::FieldDescriptor& f, uint64_t& out) {
    out = m.GetReflection()->GetUInt64(m, &f);
  }
  static void Get(const google::protobuf::Message& m,
                  const google::protobuf::FieldDescriptor& f,
                  std::vector<int64_t>& out) {
    const auto* reflection = m.GetReflection();
    out.clear();
    for (int i = 0; i < reflection->FieldSize(m, &f); ++i) {
      out.push_back(reflection->GetRepeatedInt64(m, &f, i));
    }
  }
  static void Get(const google::protobuf::Message& m,
                  const google::protobuf::FieldDescriptor& f, double& out) {
    out = m.GetReflection()->GetDouble(m, &f);
  }
  static void Get(const google::protobuf::Message& m,
                  const google::protobuf::FieldDescriptor& f, bool& out) {
    out = m.GetReflection()->GetBool(m, &f);
  }
  static void Get(const google::protobuf::Message& m,
                  const google::protobuf::FieldDescriptor& f,
                  std::string& out) {
    out = m.GetReflection()->GetString(m, &f);
  }
  static void Set(int value, const google::protobuf::FieldDescriptor& f,
                  google::protobuf::Message& m) {
    m.GetReflection()->SetInt32(&m, &f, value);
  }
  static void Set(int64_t value, const google::protobuf::FieldDescriptor& f,
                  google::protobuf::Message& m) {
    m.GetReflection()->SetInt64(&m, &f, value);
  }
  static void Set(uint64_t value, const google::protobuf::FieldDescriptor& f,
                  google::protobuf::Message& m) {
    m.GetReflection()->SetUInt64(&m, &f, value);
  }
  static void Set(const std::vector<int64_t>& values,
                  const google::protobuf::FieldDescriptor& f,
                  google::protobuf::Message& m) {
    m.GetReflection()->ClearField(&m, &f);
    for (int64_t value : values) m.GetReflection()->AddInt64(&m, &f, value);
  }
  static void Set(double value, const google::protobuf::FieldDescriptor& f,
                  google::protobuf::Message& m) {
    m.GetReflection()->SetDouble(&m, &f, value);
  }
  static void Set(bool value, const google::protobuf::FieldDescriptor& f,
                  google::protobuf::Message& m) {
    m.GetReflection()->SetBool(&m, &f, value);
  }
  static void Set(const std::string& value,
                  const google::protobuf::FieldDescriptor& f,
                  google::protobuf::Message& m) {
    m.GetReflection()->SetString(&m, &f, value);
  }

  [[noreturn]] static void Abort(const char* section, const Row& row,
                                 const char* what) {
    std::fprintf(stderr, "%s.%s %s\n", section, row.field, what);
    std::abort();
  }

  // NaN is in no range.
  static bool InRange(double value, const Row& row) {
    if (row.low.has_value() && !(row.low->inclusive ? value >= row.low->value
                                                    : value > row.low->value)) {
      return false;
    }
    if (row.high.has_value() &&
        !(row.high->inclusive ? value <= row.high->value
                              : value < row.high->value)) {
      return false;
    }
    return value == value;
  }

  static std::string Range(const Row& row) {
    if (!row.high.has_value()) {
      return absl::StrCat(row.low->inclusive ? ">= " : "> ", row.low->value);
    }
    if (!row.low.has_value()) {
      return absl::StrCat(row.high->inclusive ? "<= " : "< ", row.high->value);
    }
    return absl::StrCat("in ", row.low->inclusive ? "[" : "(", row.low->value,
                        ", ", row.high->value, row.high->inclusive ? "]" : ")");
  }

  const char* section_;
  SettingNames names_;
  std::vector<Row> rows_;
};

}  // namespace vantage

#endif  // VANTAGE_PROTO_SETTINGS_TABLE_H_
