#include "deploy/cli/plot_command.h"

#include <string>
#include <vector>

#include "deploy/cli/python_script.h"

namespace vantage {
namespace {

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

std::string ScriptHelp() {
  return PythonScriptHelp(
      kScript,
      "usage: vantage plot RUN_DIR... --out=FILE.png [flags]\n\n  (the "
      "plotting script cannot run: see docs/plotting.md)\n");
}

int RunPlot(const std::vector<std::string>&) {
  return ExecPythonScript("plot", kScript, PlotArguments());
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
