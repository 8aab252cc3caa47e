#include "deploy/cli/plot_command.h"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"

namespace vantage {
namespace {

// Debian's interpreter, which has python3-matplotlib: a python3 earlier on
// PATH (a virtualenv, pyenv) may not.
constexpr char kPython[] = "/usr/bin/python3";
constexpr char kScript[] = VANTAGE_PLOT_SCRIPT;

// Everything after `plot`, kept from absl (the script parses it).
std::vector<std::string>& PlotArguments() {
  static auto* arguments = new std::vector<std::string>();
  return *arguments;
}

void TakeArguments(std::vector<char*>& argv) {
  PlotArguments().assign(argv.begin() + 2, argv.end());
  argv.resize(2);
}

absl::Status CheckInstalled() {
  for (const char* path : {kPython, kScript}) {
    if (!std::filesystem::exists(path)) {
      return absl::FailedPreconditionError(absl::StrCat(
          path, " is missing (deploy/setup.sh installs python3-matplotlib)"));
    }
  }
  return absl::OkStatus();
}

std::string ScriptHelp() {
  const std::string fallback =
      "usage: vantage plot RUN_DIR... --out=FILE.png [flags]\n\n  (the "
      "plotting script cannot run: see docs/plotting.md)\n";
  if (!CheckInstalled().ok()) return fallback;
  FILE* pipe =
      popen(absl::StrCat(kPython, " '", kScript, "' --help").c_str(), "r");
  if (pipe == nullptr) return fallback;
  std::string text;
  char buffer[4096];
  size_t read = 0;
  while ((read = std::fread(buffer, 1, sizeof(buffer), pipe)) > 0) {
    text.append(buffer, read);
  }
  return pclose(pipe) == 0 && !text.empty() ? text : fallback;
}

int RunPlot(const std::vector<std::string>&) {
  if (absl::Status installed = CheckInstalled(); !installed.ok()) {
    return CommandFailure("plot", kRuntimeError,
                          std::string(installed.message()));
  }
  std::vector<std::string> args = {kPython, kScript};
  args.insert(args.end(), PlotArguments().begin(), PlotArguments().end());
  std::vector<char*> argv;
  for (std::string& arg : args) argv.push_back(arg.data());
  argv.push_back(nullptr);
  std::fflush(nullptr);
  // The script's exit code (0, 1 or 2, its own one-line errors) is ours.
  execv(kPython, argv.data());
  return CommandFailure(
      "plot", kRuntimeError,
      absl::StrCat("cannot run ", kPython, ": ", std::strerror(errno)));
}

}  // namespace

Command PlotCommand() {
  Command command;
  command.name = "plot";
  command.summary =
      "learning-curve figures from run directories (mean and band over "
      "seeds)";
  command.usage = "vantage plot RUN_DIR... --out=FILE.png [flags]";
  command.help = ScriptHelp;
  command.take_own_arguments = TakeArguments;
  command.takes_arguments = true;
  command.run = RunPlot;
  return command;
}

}  // namespace vantage
