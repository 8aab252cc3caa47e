#ifndef VANTAGE_LEARNER_ALGORITHMS_SETTINGS_TABLE_H_
#define VANTAGE_LEARNER_ALGORITHMS_SETTINGS_TABLE_H_

// An algorithm's settings, each declared once: the config member, the
// field of its settings message with the same name, and the range the
// config's Validate() holds it to. Reading the message, writing it back and
// checking the ranges all walk the one table, by the message's reflection.
// Only the algorithms' config sources include this (it brings protobuf).

#include <google/protobuf/descriptor.h>
#include <google/protobuf/message.h>

#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"

namespace vantage {

// One end of a setting's range.
struct SettingBound {
  double value = 0;
  bool inclusive = true;
};

inline SettingBound AtLeast(double value) { return {value, true}; }
inline SettingBound Above(double value) { return {value, false}; }
inline SettingBound Below(double value) { return {value, false}; }

template <typename Config, typename Settings>
class SettingsTable {
 public:
  using Member = std::variant<int Config::*, double Config::*, bool Config::*,
                              std::string Config::*>;
  struct Row {
    Row(const char* field, Member member,
        std::optional<SettingBound> low = std::nullopt,
        std::optional<SettingBound> high = std::nullopt)
        : field(field), member(member), low(low), high(high) {}
    const char* field;  // in the settings message, and the config's name
    Member member;
    std::optional<SettingBound> low;
    std::optional<SettingBound> high;
  };

  // `section` names the settings in messages ("ppo": "ppo.clip must be
  // ..."). A row whose field Settings lacks, or a range on a member that is
  // not a number (a bool, a string), is a programming error: it stops the
  // program at the first use of the table.
  SettingsTable(const char* section, std::vector<Row> rows)
      : section_(section), rows_(std::move(rows)) {
    for (const Row& row : rows_) {
      if (Settings::descriptor()->FindFieldByName(row.field) == nullptr) {
        Abort(section, row, "settings have no such field");
      }
      const bool number = std::holds_alternative<int Config::*>(row.member) ||
                          std::holds_alternative<double Config::*>(row.member);
      if (!number && (row.low.has_value() || row.high.has_value())) {
        Abort(section, row, "is not a number and can have no range");
      }
    }
  }

  // Each member whose field `settings` holds, over the config's defaults.
  void Read(const Settings& settings, Config& config) const {
    const auto* reflection = settings.GetReflection();
    for (const Row& row : rows_) {
      const google::protobuf::FieldDescriptor* field = Field(settings, row);
      if (!reflection->HasField(settings, field)) continue;
      std::visit([&](auto member) { Get(settings, *field, config.*member); },
                 row.member);
    }
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
            if constexpr (std::is_arithmetic_v<Value>) return config.*member;
            return 0.0;
          },
          row.member);
      if (InRange(value, row)) continue;
      return absl::InvalidArgumentError(
          absl::StrCat(section_, ".", row.field, " must be ", Range(row)));
    }
    return absl::OkStatus();
  }

 private:
  static const google::protobuf::FieldDescriptor* Field(
      const google::protobuf::Message& settings, const Row& row) {
    return settings.GetDescriptor()->FindFieldByName(row.field);
  }

  static void Get(const google::protobuf::Message& m,
                  const google::protobuf::FieldDescriptor& f, int& out) {
    out = m.GetReflection()->GetInt32(m, &f);
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
  std::vector<Row> rows_;
};

}  // namespace vantage

#endif  // VANTAGE_LEARNER_ALGORITHMS_SETTINGS_TABLE_H_
