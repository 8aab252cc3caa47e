#include "deploy/cli/experiment_command.h"

#include <fnmatch.h>

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "absl/flags/flag.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "actor/envs/env_registry.h"
#include "deploy/cli/command_line.h"
#include "deploy/cli/python_script.h"
#include "deploy/cli/run_flags.h"
#include "deploy/cli/shared_flags.h"
#include "deploy/cli/stop_signal.h"
#include "deploy/experiment/experiment_backend.h"
#include "deploy/experiment/experiment_grid.h"
#include "deploy/experiment/experiment_runner.h"

ABSL_FLAG(int, jobs, 0,
          "run: cells at a time (0: as many as the cores allow, a core per "
          "process of a cell)");
ABSL_FLAG(double, budget, 1.0,
          "run: every cell's steps times this (0.1: a tenth of the "
          "experiment)");
ABSL_FLAG(std::vector<std::string>, seeds, {},
          "run: these seeds instead of the file's (comma-separated)");
ABSL_FLAG(bool, dry_run, false,
          "run: print the cells and their commands, run nothing");
ABSL_FLAG(std::vector<std::string>, only, {},
          "run: only the cells whose directory (<env>/<group>/seed-<s>) "
          "matches one of these shell patterns (comma-separated), e.g. "
          "'Hopper/*' or '*/max-*'");
ABSL_FLAG(std::string, backend, "local",
          "run: where the cells run (local: this machine's processes; slurm: "
          "a job array, --jobs tasks at a time)");
ABSL_FLAG(std::vector<std::string>, sbatch_args, {},
          "run, --backend=slurm: more sbatch options, comma-separated (e.g. "
          "--partition=cpu,--time=04:00:00)");

namespace vantage {
namespace {

constexpr char kReportScript[] = VANTAGE_REPORT_SCRIPT;
constexpr char kName[] = "experiment";

int Fail(int code, absl::string_view message) {
  return CommandFailure(kName, code, std::string(message));
}

// `report`'s arguments, kept from absl: the script parses them.
std::vector<std::string>& ReportArguments() {
  static auto* arguments = new std::vector<std::string>();
  return *arguments;
}
bool& IsReport() {
  static bool report = false;
  return report;
}

void TakeArguments(std::vector<char*>& argv) {
  if (argv.size() < 3 || std::string(argv[2]) != "report") return;
  IsReport() = true;
  ReportArguments().assign(argv.begin() + 3, argv.end());
  argv.resize(2);
}

}  // namespace

RunSettingsSchema ExperimentRunSchema() {
  RunSettingsSchema schema;
  schema.flags = RunSettingNames();
  schema.resolve =
      [](const pb::RunConfig& base,
         const FlagSettings& settings) -> absl::StatusOr<pb::RunConfig> {
    absl::StatusOr<RunRequest> request = RunRequestFromSettings(settings);
    if (!request.ok()) return request.status();
    request->config = base;
    request->config_file = "the experiment's base";
    absl::StatusOr<ResolvedRun> run = ResolveRunRequest(*request);
    if (!run.ok()) return run.status();
    // What `train` checks when a run starts, checked before any runs.
    const std::vector<std::string> envs = RegisteredEnvironments();
    if (std::find(envs.begin(), envs.end(), run->config.training().env()) ==
        envs.end()) {
      return absl::InvalidArgumentError(absl::StrCat(
          "--env '", run->config.training().env(),
          "' is not an environment; registered: ", absl::StrJoin(envs, ", ")));
    }
    return run->config;
  };
  return schema;
}

namespace {

absl::StatusOr<std::vector<uint64_t>> SeedsFlag() {
  std::vector<uint64_t> seeds;
  for (const std::string& text : absl::GetFlag(FLAGS_seeds)) {
    uint64_t seed = 0;
    if (!absl::SimpleAtoi(text, &seed)) {
      return absl::InvalidArgumentError(
          absl::StrCat("--seeds entry '", text, "' is not a seed"));
    }
    seeds.push_back(seed);
  }
  return seeds;
}

// Keeps the cells that --only's patterns select.
absl::Status SelectCells(pb::ExpandedExperiment& experiment) {
  const std::vector<std::string> patterns = absl::GetFlag(FLAGS_only);
  if (patterns.empty()) return absl::OkStatus();
  google::protobuf::RepeatedPtrField<pb::ExperimentCell> kept;
  for (pb::ExperimentCell& cell : *experiment.mutable_cells()) {
    for (const std::string& pattern : patterns) {
      if (fnmatch(pattern.c_str(), cell.dir().c_str(), 0) == 0) {
        *kept.Add() = std::move(cell);
        break;
      }
    }
  }
  if (kept.empty()) {
    return absl::InvalidArgumentError(
        absl::StrCat("--only=", absl::StrJoin(patterns, ","),
                     " matches none of the ", experiment.cells_size(),
                     " cells (the first: ", experiment.cells(0).dir(), ")"));
  }
  experiment.mutable_cells()->Swap(&kept);
  return absl::OkStatus();
}

void PrintDryRun(const pb::ExpandedExperiment& experiment,
                 const ExperimentDirectory& directory) {
  for (const pb::ExperimentCell& cell : experiment.cells()) {
    std::printf(
        "%s  (%ld steps)\n  vantage %s\n", cell.dir().c_str(),
        static_cast<long>(cell.config().training().steps()),
        absl::StrJoin(TrainArguments(directory, cell, false), " ").c_str());
  }
  std::printf("%d cells, %d at a time by default; nothing run (--dry_run)\n",
              experiment.cells_size(), DefaultJobs(experiment));
}

struct GridFlags {
  std::string out;
  bool dry_run = false;
  std::string backend;
  std::vector<uint64_t> seeds;
};

// An error's message is the usage error to print.
absl::StatusOr<GridFlags> ReadGridFlags() {
  GridFlags flags;
  flags.out = absl::GetFlag(FLAGS_out);
  flags.dry_run = absl::GetFlag(FLAGS_dry_run);
  if (flags.out.empty() && !flags.dry_run) {
    return absl::InvalidArgumentError("run needs --out=EXP_DIR");
  }
  if (absl::GetFlag(FLAGS_jobs) < 0) {
    return absl::InvalidArgumentError(
        "--jobs must be >= 0 (0: as the cores allow)");
  }
  absl::StatusOr<std::vector<uint64_t>> seeds = SeedsFlag();
  if (!seeds.ok()) return seeds.status();
  flags.seeds = *std::move(seeds);
  flags.backend = absl::GetFlag(FLAGS_backend);
  if (absl::StatusOr<std::unique_ptr<ExperimentBackend>> made =
          MakeExperimentBackend(flags.backend, BackendOptions());
      !made.ok()) {
    return absl::InvalidArgumentError(
        absl::StrCat("--backend: ", made.status().message()));
  }
  if (!absl::GetFlag(FLAGS_sbatch_args).empty() && flags.backend != "slurm") {
    return absl::InvalidArgumentError(
        "--sbatch_args goes with --backend=slurm");
  }
  return flags;
}

// The experiment file and the cells of it that --only selects.
struct GridPlan {
  pb::Experiment experiment;
  pb::ExpandedExperiment expanded;
};

// An error's message is the usage error to print.
absl::StatusOr<GridPlan> PlanGrid(const std::string& file,
                                  const GridFlags& flags) {
  GridPlan plan;
  absl::StatusOr<pb::Experiment> experiment = ReadExperimentFile(file);
  if (!experiment.ok()) return experiment.status();
  plan.experiment = *std::move(experiment);
  ExpandOptions options;
  options.file = file;
  options.budget = absl::GetFlag(FLAGS_budget);
  options.seeds = flags.seeds;
  absl::StatusOr<pb::ExpandedExperiment> expanded =
      ExpandExperiment(plan.experiment, options, ExperimentRunSchema());
  if (!expanded.ok()) return expanded.status();
  plan.expanded = *std::move(expanded);
  if (absl::Status status = SelectCells(plan.expanded); !status.ok()) {
    return status;
  }
  return plan;
}

int RunCells(const GridPlan& plan, const GridFlags& flags) {
  ExperimentRunOptions run_options;
  run_options.exp_dir = flags.out;
  run_options.backend = flags.backend;
  run_options.jobs = absl::GetFlag(FLAGS_jobs);
  run_options.scheduler_args = absl::GetFlag(FLAGS_sbatch_args);
  const absl::Status status = RunExperiment(
      plan.expanded, plan.experiment.base(), run_options, StopRequested());
  if (absl::IsFailedPrecondition(status)) {
    return Fail(kUsageError, status.message());
  }
  if (!status.ok()) return Fail(kRuntimeError, status.message());
  return 0;
}

int RunGrid(const std::vector<std::string>& args) {
  if (args.size() != 2) {
    return Fail(kUsageError,
                "usage: vantage experiment run FILE --out=EXP_DIR [flags]");
  }
  absl::StatusOr<GridFlags> flags = ReadGridFlags();
  if (!flags.ok()) return Fail(kUsageError, flags.status().message());
  absl::StatusOr<GridPlan> plan = PlanGrid(args[1], *flags);
  if (!plan.ok()) return Fail(kUsageError, plan.status().message());
  const ExperimentDirectory directory(flags->out.empty() ? "EXP_DIR"
                                                         : flags->out);
  if (flags->dry_run) {
    if (!flags->out.empty()) {
      if (absl::Status status = directory.CheckRuns(plan->expanded);
          !status.ok()) {
        return Fail(kUsageError, status.message());
      }
    }
    PrintDryRun(plan->expanded, directory);
    return 0;
  }
  return RunCells(*plan, *flags);
}

int RunExperimentCommand(const std::vector<std::string>& args) {
  if (IsReport()) {
    return ExecPythonScript("experiment report", kReportScript,
                            ReportArguments());
  }
  if (args.empty() || args[0] != "run") {
    return Fail(
        kUsageError,
        absl::StrCat(args.empty() ? "no subcommand"
                                  : "unknown subcommand '" + args[0] + "'",
                     "; use `vantage experiment run FILE "
                     "--out=EXP_DIR` or `vantage experiment report "
                     "EXP_DIR`"));
  }
  return RunGrid(args);
}

Command BaseCommand() {
  Command command;
  command.name = kName;
  command.summary =
      "grids of seeded runs from an experiment file, and their report";
  command.usage =
      "vantage experiment run FILE --out=EXP_DIR [flags]\n"
      "       vantage experiment report EXP_DIR [report flags]";
  command.description =
      "run: expands the experiment FILE (configs/experiments/*.json) into\n"
      "cells, one `vantage train` run each in EXP_DIR/<env>/<group>/seed-<s>,\n"
      "and runs them --jobs at a time. Running it again skips finished\n"
      "cells and resumes interrupted ones from their checkpoints; SIGINT or\n"
      "SIGTERM stops every cell with a checkpoint; a failed cell is reported\n"
      "and the others go on. report: see below. docs/experiments.md.";
  command.flags = {"out",     "jobs", "budget",  "seeds",
                   "dry_run", "only", "backend", "sbatch_args"};
  command.defaults["backend"] = absl::StrCat(
      "local (backends: ", absl::StrJoin(ExperimentBackendNames(), ", "), ")");
  command.example =
      "vantage experiment run configs/experiments/mujoco.json "
      "--out=experiments/mujoco --budget=0.3 --seeds=0,1,2";
  return command;
}

std::string Help() {
  return absl::StrCat(
      CommandHelp(BaseCommand()), "\n",
      PythonScriptHelp(kReportScript,
                       "usage: vantage experiment report EXP_DIR [flags]\n\n"
                       "  (the report script cannot run: see "
                       "docs/experiments.md)\n"));
}

}  // namespace

Command ExperimentCommand() {
  Command command = BaseCommand();
  command.help = Help;
  command.take_own_arguments = TakeArguments;
  command.takes_arguments = true;
  command.run = RunExperimentCommand;
  return command;
}

}  // namespace vantage
