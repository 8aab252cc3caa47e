#include "deploy/cli/commands.h"

#include <algorithm>

#include "deploy/cli/actor_command.h"
#include "deploy/cli/advantages_command.h"
#include "deploy/cli/bench_command.h"
#include "deploy/cli/env_commands.h"
#include "deploy/cli/experiment_command.h"
#include "deploy/cli/export_command.h"
#include "deploy/cli/health_command.h"
#include "deploy/cli/learner_command.h"
#include "deploy/cli/plot_command.h"
#include "deploy/cli/train_command.h"

namespace vantage {

const std::vector<Command>& AllCommands() {
  static const auto* commands = [] {
    auto* all = new std::vector<Command>{
        ActorCommand(),   AdvantagesCommand(), BenchCommand(),
        EnvsCommand(),    ExperimentCommand(), ExportCommand(),
        HealthCommand(),  LearnerCommand(),    PlotCommand(),
        RolloutCommand(), TrainCommand(),
    };
    std::sort(all->begin(), all->end(), [](const Command& a, const Command& b) {
      return a.name < b.name;
    });
    return all;
  }();
  return *commands;
}

}  // namespace vantage
