#include "actor/envs/env_options.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"

namespace vantage {
namespace {

struct TextOf {
  std::string operator()(double* value) const {
    return absl::StrFormat("%g", *value);
  }
  std::string operator()(int* value) const { return absl::StrCat(*value); }
  std::string operator()(int64_t* value) const { return absl::StrCat(*value); }
  std::string operator()(bool* value) const {
    return *value ? "true" : "false";
  }
};

}  // namespace

std::string EnvOption::Text() const { return std::visit(TextOf(), field); }

absl::Status EnvOption::Set(absl::string_view value) const {
  auto bad = [&](absl::string_view what) {
    return absl::InvalidArgumentError(
        absl::StrCat("env option ", name, "=", value, " is not ", what));
  };
  if (auto* target = std::get_if<double*>(&field)) {
    double parsed = 0;
    if (!absl::SimpleAtod(value, &parsed) || !std::isfinite(parsed)) {
      return bad("a finite number");
    }
    **target = parsed;
  } else if (auto* target = std::get_if<int*>(&field)) {
    if (!absl::SimpleAtoi(value, *target)) return bad("an integer");
  } else if (auto* target = std::get_if<int64_t*>(&field)) {
    if (!absl::SimpleAtoi(value, *target)) return bad("an integer");
  } else if (auto* target = std::get_if<bool*>(&field)) {
    if (!absl::SimpleAtob(value, *target)) return bad("true or false");
    return absl::OkStatus();
  }
  double number = 0;
  (void)absl::SimpleAtod(Text(), &number);
  if (min.has_value() && number < *min) {
    return bad(absl::StrFormat("at least %g", *min));
  }
  return absl::OkStatus();
}

std::vector<EnvOptionInfo> Describe(const std::vector<EnvOption>& options) {
  std::vector<EnvOptionInfo> described;
  for (const EnvOption& option : options) {
    described.push_back({option.name, option.Text(), option.help});
  }
  return described;
}

std::string EnvName::Canonical() const {
  if (options.empty()) return task;
  std::vector<std::string> pairs;
  for (const auto& [key, value] : options) {
    pairs.push_back(absl::StrCat(key, "=", value));
  }
  return absl::StrCat(task, ":", absl::StrJoin(pairs, ","));
}

absl::StatusOr<EnvName> ParseEnvName(absl::string_view name) {
  EnvName parsed;
  const size_t colon = name.find(':');
  parsed.task = std::string(name.substr(0, colon));
  if (colon == absl::string_view::npos) return parsed;
  for (absl::string_view pair : absl::StrSplit(name.substr(colon + 1), ',')) {
    const size_t equals = pair.find('=');
    const absl::string_view key =
        absl::StripAsciiWhitespace(pair.substr(0, equals));
    if (equals == absl::string_view::npos || key.empty()) {
      return absl::InvalidArgumentError(absl::StrCat(
          name, ": '", pair, "' is no option; write TASK:KEY=VALUE,KEY=VALUE"));
    }
    parsed.options.emplace_back(
        std::string(key),
        std::string(absl::StripAsciiWhitespace(pair.substr(equals + 1))));
  }
  std::sort(parsed.options.begin(), parsed.options.end());
  for (size_t i = 1; i < parsed.options.size(); ++i) {
    if (parsed.options[i].first == parsed.options[i - 1].first) {
      return absl::InvalidArgumentError(absl::StrCat(
          name, ": the option ", parsed.options[i].first, " is given twice"));
    }
  }
  return parsed;
}

absl::Status ApplyEnvOptions(absl::string_view task,
                             const std::vector<EnvOption>& options,
                             const EnvOptionValues& values) {
  for (const auto& [key, value] : values) {
    auto option = std::find_if(
        options.begin(), options.end(),
        [&key = key](const EnvOption& o) { return o.name == key; });
    if (option == options.end()) {
      std::vector<std::string> names;
      for (const EnvOption& o : options) names.push_back(o.name);
      return absl::InvalidArgumentError(absl::StrCat(
          task, " has no option '", key, "'",
          names.empty()
              ? "; it takes none"
              : absl::StrCat("; its options: ", absl::StrJoin(names, ", "))));
    }
    if (absl::Status status = option->Set(value); !status.ok()) {
      return absl::InvalidArgumentError(
          absl::StrCat(task, ": ", status.message()));
    }
  }
  return absl::OkStatus();
}

}  // namespace vantage
