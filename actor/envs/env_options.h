#ifndef VANTAGE_ACTOR_ENVS_ENV_OPTIONS_H_
#define VANTAGE_ACTOR_ENVS_ENV_OPTIONS_H_

// A task with other settings is the same task, named with them:
// `HalfCheetah:ctrl_cost=0.2,max_episode_steps=500` is HalfCheetah with
// those two options changed. Each task declares the options it takes, bound
// to the fields of its own description, so the defaults shown are the ones
// it runs with.

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace vantage {

// (option, value as written) pairs, sorted by option.
using EnvOptionValues = std::vector<std::pair<std::string, std::string>>;

// One option of a task: a field of its description, and the lowest value
// it takes (numbers only).
struct EnvOption {
  using Field = std::variant<double*, int*, int64_t*, bool*>;
  EnvOption(std::string name, std::string help, Field field,
            std::optional<double> min = std::nullopt)
      : name(std::move(name)), help(std::move(help)), field(field), min(min) {}

  std::string name;
  std::string help;
  Field field;
  std::optional<double> min;

  // The field's value as an option value ("0.1", "500", "true").
  std::string Text() const;
  // Sets the field; InvalidArgument naming the option for a value of the
  // wrong type or a non-finite number.
  absl::Status Set(absl::string_view value) const;
};

// An option as `vantage envs` lists it: its name, the task's default and
// its help.
struct EnvOptionInfo {
  std::string name;
  std::string default_value;
  std::string help;
};
std::vector<EnvOptionInfo> Describe(const std::vector<EnvOption>& options);

// What a name with options says.
struct EnvName {
  std::string task;         // "HalfCheetah"
  EnvOptionValues options;  // sorted; empty for a plain name
  // "HalfCheetah:ctrl_cost=0.2,max_episode_steps=500": the task and its
  // options sorted, the name its spec carries.
  std::string Canonical() const;
};

// Splits "TASK[:KEY=VALUE,...]"; a malformed list or a repeated option is
// InvalidArgument.
absl::StatusOr<EnvName> ParseEnvName(absl::string_view name);

// Sets each given option; an unknown one is InvalidArgument naming the task
// and listing the options it has.
absl::Status ApplyEnvOptions(absl::string_view task,
                             const std::vector<EnvOption>& options,
                             const EnvOptionValues& values);

}  // namespace vantage

#endif  // VANTAGE_ACTOR_ENVS_ENV_OPTIONS_H_
