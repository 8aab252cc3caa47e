#include "deploy/cli/command_line.h"

#include <algorithm>
#include <cstdio>
#include <deque>
#include <fstream>
#include <map>
#include <optional>
#include <set>

#include "absl/flags/commandlineflag.h"
#include "absl/flags/internal/parse.h"
#include "absl/flags/parse.h"
#include "absl/flags/reflection.h"
#include "absl/status/status.h"
#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_replace.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"

namespace vantage {
namespace {

// absl's own flags that read more flags; every command takes them.
const std::set<std::string, std::less<>>& FlagSourceFlags() {
  static const auto* names = new std::set<std::string, std::less<>>{
      "flagfile", "fromenv", "tryfromenv"};
  return *names;
}

bool IsHelpArgument(absl::string_view arg) {
  return arg == "-h" || arg == "--help" || arg == "-help" ||
         arg == "--helpfull" || arg == "-helpfull" || arg == "--helpshort" ||
         arg == "-helpshort";
}

bool Owns(const Command& command, absl::string_view flag) {
  return std::find(command.flags.begin(), command.flags.end(), flag) !=
         command.flags.end();
}

absl::Status NotOwn(const Command& command, absl::string_view flag) {
  return absl::InvalidArgumentError(
      absl::StrCat("--", flag, " is not a flag of `vantage ", command.name,
                   "` (see `vantage help ", command.name, "`)"));
}

// The values given to declared flags, by name.
std::map<std::string, std::string, std::less<>>& DeclaredValues() {
  static auto* values = new std::map<std::string, std::string, std::less<>>;
  return *values;
}

// A flag of the command line: an absl flag or a declared one (of any
// command, so that another command's flag is named as such).
struct FoundFlag {
  absl::CommandLineFlag* absl_flag = nullptr;
  const DeclaredFlag* declared = nullptr;
  bool boolean() const {
    return absl_flag != nullptr ? absl_flag->IsOfType<bool>()
                                : declared->boolean;
  }
  absl::Status Check(absl::string_view name, const std::string& value) const {
    if (declared != nullptr) return declared->check(value);
    std::string error;
    if (absl_flag->ParseFrom(value, &error)) return absl::OkStatus();
    return absl::InvalidArgumentError(
        absl::StrCat("--", name, "=", value, ": ", error));
  }
};

std::optional<FoundFlag> FindFlag(const Command& command,
                                  absl::string_view name) {
  if (absl::CommandLineFlag* flag = absl::FindCommandLineFlag(name)) {
    return FoundFlag{flag, nullptr};
  }
  for (const DeclaredFlag& declared : command.declared_flags) {
    if (declared.name == name) return FoundFlag{nullptr, &declared};
  }
  return std::nullopt;
}

// The command's own flag first, so that its check is the one that runs.
std::optional<FoundFlag> FindFlag(const std::vector<Command>& commands,
                                  const Command& command,
                                  absl::string_view name) {
  if (std::optional<FoundFlag> own = FindFlag(command, name)) return own;
  for (const Command& other : commands) {
    if (std::optional<FoundFlag> found = FindFlag(other, name)) return found;
  }
  return std::nullopt;
}

// The flags on the command line itself, each checked to be the command's
// own and to parse, so that a mistake is a message naming the command and
// exit 2 rather than absl's exit 1. Flags inside --flagfile files are
// on the command line by then (ExpandFlagfiles). Declared flags are taken
// out of `arguments` into DeclaredValues; absl parses the rest.
absl::Status TakeCommandLineFlags(const std::vector<Command>& commands,
                                  const Command& command,
                                  std::vector<char*>& arguments) {
  std::vector<char*> kept(arguments.begin(), arguments.begin() + 2);
  for (size_t i = 2; i < arguments.size(); ++i) {
    absl::string_view arg = arguments[i];
    if (arg == "--") {
      kept.insert(kept.end(), arguments.begin() + i, arguments.end());
      break;
    }
    kept.push_back(arguments[i]);
    if (arg.size() < 2 || arg[0] != '-') continue;  // an argument
    arg.remove_prefix(arg[1] == '-' ? 2 : 1);
    const size_t equals = arg.find('=');
    const absl::string_view name = arg.substr(0, equals);
    const bool has_value = equals != absl::string_view::npos;
    if (FlagSourceFlags().count(name) > 0) {
      if (!has_value && i + 1 < arguments.size())
        kept.push_back(arguments[++i]);
      continue;
    }
    std::optional<FoundFlag> flag = FindFlag(commands, command, name);
    absl::string_view flag_name = name;
    std::string value = has_value ? std::string(arg.substr(equals + 1)) : "";
    if (!flag.has_value() && absl::StartsWith(name, "no") && !has_value) {
      std::optional<FoundFlag> negated =
          FindFlag(commands, command, name.substr(2));
      if (negated.has_value() && negated->boolean()) {
        flag = negated;
        flag_name = name.substr(2);
        value = "false";
      }
    }
    if (!flag.has_value()) {
      return absl::InvalidArgumentError(absl::StrCat(
          "unknown flag --", name, " (see `vantage help ", command.name, "`)"));
    }
    if (!Owns(command, flag_name)) return NotOwn(command, flag_name);
    if (!has_value && value.empty()) {
      if (flag->boolean()) {
        value = "true";
      } else if (i + 1 < arguments.size()) {
        value = arguments[++i];
        if (flag->absl_flag != nullptr) kept.push_back(arguments[i]);
      } else {
        return absl::InvalidArgumentError(
            absl::StrCat("--", name, " needs a value"));
      }
    }
    // Parsing an absl flag here only checks the value: absl sets it again.
    if (absl::Status status = flag->Check(flag_name, value); !status.ok()) {
      return status;
    }
    if (flag->declared != nullptr) {
      kept.pop_back();
      DeclaredValues()[std::string(flag_name)] = value;
    }
  }
  arguments = std::move(kept);
  return absl::OkStatus();
}

// --flagfile=FILE[,FILE...] (or --flagfile FILE) replaced by the flags in
// the files, one per line ('#' starts a comment line, blank lines are
// skipped, a file may name more files), so that their flags are checked as
// the command line's are: absl's own reading exits 1 on a mistake in them.
// The expanded arguments are kept in `storage`.
absl::Status ExpandFlagfiles(std::vector<char*>& arguments,
                             std::deque<std::string>& storage, int depth = 0) {
  if (depth > 8) {
    return absl::InvalidArgumentError(
        "--flagfile: files name each other more than 8 deep (a cycle?)");
  }
  std::vector<char*> expanded;
  for (size_t i = 0; i < arguments.size(); ++i) {
    absl::string_view arg = arguments[i];
    if (arg == "--") {
      expanded.insert(expanded.end(), arguments.begin() + i, arguments.end());
      break;
    }
    absl::string_view value;
    if (absl::ConsumePrefix(&arg, "--flagfile=") ||
        absl::ConsumePrefix(&arg, "-flagfile=")) {
      value = arg;
    } else if ((arg == "--flagfile" || arg == "-flagfile") &&
               i + 1 < arguments.size()) {
      value = arguments[++i];
    } else {
      expanded.push_back(arguments[i]);
      continue;
    }
    for (absl::string_view path : absl::StrSplit(value, ',')) {
      std::ifstream file{std::string(path)};
      if (!file) {
        return absl::InvalidArgumentError(
            absl::StrCat("--flagfile=", path, ": cannot read it"));
      }
      std::vector<char*> flags;
      std::string line;
      for (int number = 1; std::getline(file, line); ++number) {
        const absl::string_view flag = absl::StripAsciiWhitespace(line);
        if (flag.empty() || flag[0] == '#') continue;
        if (flag[0] != '-') {
          return absl::InvalidArgumentError(
              absl::StrCat("--flagfile=", path, " line ", number, ": '", flag,
                           "' is not a flag (one --name=value per line)"));
        }
        flags.push_back(storage.emplace_back(flag).data());
      }
      if (absl::Status status = ExpandFlagfiles(flags, storage, depth + 1);
          !status.ok()) {
        return status;
      }
      expanded.insert(expanded.end(), flags.begin(), flags.end());
    }
  }
  arguments = std::move(expanded);
  return absl::OkStatus();
}

// Flags set from the environment (--fromenv) are held to the same rule.
absl::Status CheckFlagsFromEnvironment(const Command& command) {
  std::vector<std::string> names;
  for (const auto& [name, flag] : absl::GetAllFlags()) {
    if (FlagSourceFlags().count(name) == 0 && FlagGiven(name) &&
        !Owns(command, name)) {
      names.emplace_back(name);
    }
  }
  if (names.empty()) return absl::OkStatus();
  std::sort(names.begin(), names.end());
  return NotOwn(command, names.front());
}

const Command* Find(const std::vector<Command>& commands,
                    absl::string_view name) {
  for (const Command& command : commands) {
    if (command.name == name) return &command;
  }
  return nullptr;
}

std::string Names(const std::vector<Command>& commands) {
  std::vector<std::string> names;
  for (const Command& command : commands) names.push_back(command.name);
  return absl::StrJoin(names, ", ");
}

int Help(const std::vector<Command>& commands,
         const std::vector<std::string>& args) {
  if (args.empty()) {
    std::printf("%s", OverviewHelp(commands).c_str());
    return 0;
  }
  const Command* command = Find(commands, args[0]);
  if (args.size() > 1 || command == nullptr) {
    std::fprintf(stderr,
                 "vantage help: name one command of: %s (or none for all)\n",
                 Names(commands).c_str());
    return kUsageError;
  }
  std::printf("%s", CommandHelp(*command).c_str());
  return 0;
}

}  // namespace

int CommandFailure(const std::string& command, int code,
                   const std::string& message) {
  std::fprintf(stderr, "vantage %s: %s\n", command.c_str(),
               absl::StrReplaceAll(message, {{"\n", " "}}).c_str());
  return code;
}

bool FlagGiven(absl::string_view name) {
  return DeclaredValues().count(name) > 0 ||
         absl::flags_internal::WasPresentOnCommandLine(name);
}

std::optional<std::string> DeclaredFlagValue(absl::string_view name) {
  auto it = DeclaredValues().find(name);
  if (it == DeclaredValues().end()) return std::nullopt;
  return it->second;
}

std::string CommandHelp(const Command& command) {
  if (command.help) return command.help();
  std::string text = absl::StrCat("usage: ", command.usage, "\n\n");
  for (absl::string_view line : absl::StrSplit(command.description, '\n')) {
    absl::StrAppend(&text, "  ", line, "\n");
  }
  absl::StrAppend(&text, "\nflags:\n");
  for (const std::string& name : command.flags) {
    const std::optional<FoundFlag> flag = FindFlag(command, name);
    if (!flag.has_value()) continue;  // a programming error, caught by a test
    const auto own = command.defaults.find(name);
    const std::string value = own != command.defaults.end() ? own->second
                              : flag->absl_flag != nullptr
                                  ? flag->absl_flag->DefaultValue()
                                  : "";
    absl::StrAppend(&text, "  --", name, "=", value.empty() ? "\"\"" : value,
                    "\n");
    absl::StrAppend(&text, "      ",
                    flag->absl_flag != nullptr ? flag->absl_flag->Help()
                                               : flag->declared->help,
                    "\n");
  }
  absl::StrAppend(&text,
                  "  --flagfile=FILE\n"
                  "      more flags from FILE, one per line (same result as "
                  "on the command line)\n");
  absl::StrAppend(&text, "\nexample:\n  ", command.example, "\n");
  return text;
}

std::string OverviewHelp(const std::vector<Command>& commands) {
  std::string text =
      "usage: vantage <command> [flags] [arguments]\n\ncommands:\n";
  size_t width = 4;
  for (const Command& command : commands) {
    width = std::max(width, command.name.size());
  }
  for (const Command& command : commands) {
    absl::StrAppend(&text, "  ", command.name,
                    std::string(width + 2 - command.name.size(), ' '),
                    command.summary, "\n");
  }
  absl::StrAppend(&text, "  help", std::string(width - 2, ' '),
                  "this list, or `vantage help COMMAND` for one command\n");
  return text;
}

int RunCommandLine(const std::vector<Command>& commands, int argc,
                   char** argv) {
  if (argc < 2 || IsHelpArgument(argv[1])) {
    std::fprintf(argc < 2 ? stderr : stdout, "%s",
                 OverviewHelp(commands).c_str());
    return argc < 2 ? kUsageError : 0;
  }
  const std::string name = argv[1];
  if (name == "help") {
    return Help(commands, std::vector<std::string>(argv + 2, argv + argc));
  }
  const Command* command = Find(commands, name);
  if (command == nullptr) {
    std::fprintf(stderr, "vantage: unknown command '%s'; commands: %s, help\n",
                 name.c_str(), Names(commands).c_str());
    return kUsageError;
  }
  for (int i = 2; i < argc && std::string(argv[i]) != "--"; ++i) {
    if (IsHelpArgument(argv[i])) {
      std::printf("%s", CommandHelp(*command).c_str());
      return 0;
    }
  }
  std::vector<char*> arguments(argv, argv + argc);
  if (command->take_own_arguments) command->take_own_arguments(arguments);
  std::deque<std::string> from_files;
  if (absl::Status status = ExpandFlagfiles(arguments, from_files);
      !status.ok()) {
    return CommandFailure(name, kUsageError, std::string(status.message()));
  }
  if (absl::Status status = TakeCommandLineFlags(commands, *command, arguments);
      !status.ok()) {
    return CommandFailure(name, kUsageError, std::string(status.message()));
  }
  argc = static_cast<int>(arguments.size());
  argv = arguments.data();
  const std::vector<char*> positional = absl::ParseCommandLine(argc, argv);
  if (absl::Status status = CheckFlagsFromEnvironment(*command); !status.ok()) {
    return CommandFailure(name, kUsageError, std::string(status.message()));
  }
  // positional[0] is the program, positional[1] the command.
  const std::vector<std::string> args(positional.begin() + 2, positional.end());
  if (!args.empty() && !command->takes_arguments) {
    return CommandFailure(name, kUsageError,
                          absl::StrCat("unexpected argument '", args[0], "'"));
  }
  return command->run(args);
}

}  // namespace vantage
