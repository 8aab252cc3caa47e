#include "deploy/cli/python_script.h"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "absl/strings/str_cat.h"
#include "deploy/cli/command.h"
#include "deploy/cli/resolved_run_configs.h"

namespace vantage {
namespace {

// Debian's interpreter, which has python3-matplotlib and python3-scipy: a
// python3 earlier on PATH (a virtualenv, pyenv) may not.
constexpr char kPython[] = "/usr/bin/python3";

}  // namespace

absl::Status CheckPythonScript(const std::string& script) {
  for (const std::string& path : {std::string(kPython), script}) {
    if (!std::filesystem::exists(path)) {
      return absl::FailedPreconditionError(absl::StrCat(
          path,
          " is missing (deploy/setup.sh installs python3-matplotlib and "
          "python3-scipy)"));
    }
  }
  return absl::OkStatus();
}

std::string PythonScriptHelp(const std::string& script,
                             const std::string& fallback) {
  if (!CheckPythonScript(script).ok()) return fallback;
  FILE* pipe =
      popen(absl::StrCat(kPython, " '", script, "' --help").c_str(), "r");
  if (pipe == nullptr) return fallback;
  std::string text;
  char buffer[4096];
  size_t read = 0;
  while ((read = std::fread(buffer, 1, sizeof(buffer), pipe)) > 0) {
    text.append(buffer, read);
  }
  return pclose(pipe) == 0 && !text.empty() ? text : fallback;
}

int ExecPythonScript(const std::string& command, const std::string& script,
                     const std::vector<std::string>& args) {
  if (absl::Status installed = CheckPythonScript(script); !installed.ok()) {
    return CommandFailure(command, kRuntimeError,
                          std::string(installed.message()));
  }
  ExportResolvedRunConfigs(args);
  std::vector<std::string> all = {kPython, script};
  all.insert(all.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& arg : all) argv.push_back(arg.data());
  argv.push_back(nullptr);
  std::fflush(nullptr);
  execv(kPython, argv.data());
  return CommandFailure(
      command, kRuntimeError,
      absl::StrCat("cannot run ", kPython, ": ", std::strerror(errno)));
}

}  // namespace vantage
