#include "deploy/cli/train_command.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <vector>

#include "absl/flags/flag.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "actor/envs/env_registry.h"
#include "common/nn/compute_threads.h"
#include "common/nn/network_config.h"
#include "deploy/cli/learner_limit_flags.h"
#include "deploy/cli/run_flags.h"
#include "deploy/cli/security_flags.h"
#include "deploy/cli/shared_flags.h"
#include "deploy/cli/stop_signal.h"
#include "deploy/run/launcher.h"
#include "deploy/run/local_training.h"
#include "deploy/run/run_config.h"
#include "learner/algorithms/algorithm_config.h"
#include "learner/run/run_directory.h"

namespace vantage {
namespace {

int Fail(int code, absl::string_view message) {
  return CommandFailure("train", code, std::string(message));
}

std::string Duration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "?";
  const long s = std::lround(seconds);
  return s >= 3600 ? absl::StrCat(s / 3600, "h", (s % 3600) / 60, "m")
                   : absl::StrCat(s / 60, "m", s % 60, "s");
}

// One learner and --actors actor processes (deploy/run/launcher.h).
int RunDistributed(const ResolvedRun& run) {
  // The children read the files themselves; checked here to fail early.
  absl::StatusOr<SecurityOptions> security = SecurityFromFlags(/*server=*/true);
  if (!security.ok()) return Fail(kUsageError, security.status().message());
  LaunchConfig launch;
  launch.resume = run.plan.recording.resume;
  launch.run_config = run.config;
  launch.run_dir = run.plan.recording.run_dir;
  launch.work_dir =
      run.plan.recording.run_dir.empty()
          ? absl::StrCat(std::filesystem::temp_directory_path().string(),
                         "/vantage-launch-", ::getpid())
          : run.plan.recording.run_dir + "/launch";
  launch.auth_token_file = AuthTokenFileFlag();
  launch.tls_cert = security->tls_cert_file;
  launch.tls_key = security->tls_key_file;
  launch.tls_ca = security->tls_ca_file;
  launch.metrics_address = absl::GetFlag(FLAGS_metrics);
  launch.learner_args = GivenLearnerLimitArgs();
  std::printf(
      "%s %s with %s, estimator %s (rho %g), %ld steps, seed %lu: "
      "1 learner + %d actors x %d envs over gRPC%s%s\n",
      run.plan.recording.resume ? "resuming" : "training",
      run.config.training().env().c_str(), AlgorithmNameOf(run.config).c_str(),
      run.config.advantage().estimator().c_str(), run.config.advantage().rho(),
      static_cast<long>(run.config.training().steps()),
      static_cast<unsigned long>(run.config.training().seed()),
      run.config.distributed().actors(),
      run.config.distributed().envs_per_actor(),
      run.plan.recording.run_dir.empty() ? "" : ", run directory ",
      run.plan.recording.run_dir.c_str());
  std::fflush(stdout);
  const absl::Status status = RunDistributedTraining(launch, StopRequested());
  if (run.plan.recording.run_dir.empty()) {
    std::error_code error;
    std::filesystem::remove_all(launch.work_dir, error);
  }
  if (!status.ok()) return Fail(kRuntimeError, status.message());
  return 0;
}

void PrintLocalStart(const ResolvedRun& run) {
  const pb::RunConfig& config = run.config;
  const RecordingConfig& recording = run.plan.recording;
  std::printf(
      "%s %s with %s, estimator %s (rho %g, ensemble %s), %ld steps, seed "
      "%lu%s%s\n",
      recording.resume ? "resuming" : "training",
      config.training().env().c_str(), AlgorithmNameOf(config).c_str(),
      config.advantage().estimator().c_str(), config.advantage().rho(),
      absl::StrJoin(config.advantage().ensemble(), ",").c_str(),
      static_cast<long>(config.training().steps()),
      static_cast<unsigned long>(config.training().seed()),
      recording.run_dir.empty() ? "" : ", run directory ",
      recording.run_dir.c_str());
  std::fflush(stdout);
}

// Rewrites the terminal's last line.
void PrintProgressLine(const ProgressRow& progress, int64_t steps) {
  const double remaining =
      (steps - progress.stats.env_steps) / progress.steps_per_second;
  std::printf(
      "\r\033[Kupdate %ld  steps %ld/%ld  %.0f steps/s  "
      "return(last100) %.1f  ETA %s",
      static_cast<long>(progress.stats.policy_version),
      static_cast<long>(progress.stats.env_steps), static_cast<long>(steps),
      progress.steps_per_second, progress.mean_return,
      Duration(remaining).c_str());
  std::fflush(stdout);
}

// The last progress row a local run reported, if any.
struct LocalProgress {
  ProgressRow last;
  bool updated = false;
};

// How a local run that returned without an error ended: stopped, with
// nothing left to do, or with its result.
int FinishLocal(const ResolvedRun& run, const LocalProgress& seen,
                bool stopped) {
  const pb::RunConfig& config = run.config;
  const RecordingConfig& recording = run.plan.recording;
  if (stopped && (!seen.updated ||
                  seen.last.stats.env_steps < config.training().steps())) {
    const std::string where =
        seen.updated ? absl::StrCat("at ", seen.last.stats.env_steps, " of ",
                                    config.training().steps(), " steps")
                     : "before its first update in this process";
    std::printf("stopped %s%s%s\n", where.c_str(),
                recording.run_dir.empty() ? "" : "; continue with --resume=",
                recording.run_dir.c_str());
    return 0;
  }
  if (!seen.updated && recording.resume) {
    PrintFinishedAlready(run);
    return 0;
  }
  PrintTrainResult(config, seen.last);
  return 0;
}

int RunLocal(const ResolvedRun& run) {
  SetComputeThreads(1);
  PrintLocalStart(run);
  const int64_t steps = run.config.training().steps();
  const bool terminal = ::isatty(STDOUT_FILENO) == 1;
  LocalProgress seen;
  seen.last.mean_return = std::nan("");
  const std::atomic<bool>& stop = StopRequested();
  const absl::Status status = RunLocalTraining(
      run.plan,
      [&](const ProgressRow& progress) {
        seen.last = progress;
        seen.updated = true;
        if (terminal) PrintProgressLine(progress, steps);
        return true;
      },
      &stop);
  if (terminal) std::printf("\n");
  if (!status.ok()) return Fail(kRuntimeError, status.message());
  return FinishLocal(run, seen, stop);
}

int RunTrain(const std::vector<std::string>&) {
  absl::StatusOr<RunRequest> request = RunRequestFromFlags();
  if (!request.ok()) return Fail(kUsageError, request.status().message());
  absl::StatusOr<ResolvedRun> run = ResolveRunRequest(*request);
  if (!run.ok()) return Fail(kUsageError, run.status().message());
  if (const std::vector<std::string> limits = GivenLearnerLimitArgs();
      !limits.empty()) {
    if (run->config.mode() != "distributed") {
      return Fail(
          kUsageError,
          absl::StrCat(limits.front().substr(0, limits.front().find('=')),
                       " limits the learner of --mode=distributed; a "
                       "--mode=local run has none"));
    }
    if (absl::Status status = CheckLearnerLimits(); !status.ok()) {
      return Fail(kUsageError, status.message());
    }
  }
  if (absl::Status status = CheckRunCanStart(*run); !status.ok()) {
    return Fail(kUsageError, status.message());
  }
  if (absl::Status status = PrepareRunDirectory(*run); !status.ok()) {
    return Fail(kRuntimeError, status.message());
  }
  if (!absl::GetFlag(FLAGS_metrics).empty() &&
      run->config.mode() != "distributed") {
    return Fail(kUsageError,
                "--metrics serves the processes of --mode=distributed; a "
                "--mode=local run has none");
  }
  return run->config.mode() == "distributed" ? RunDistributed(*run)
                                             : RunLocal(*run);
}

}  // namespace

absl::Status CheckRunCanStart(const ResolvedRun& run) {
  absl::StatusOr<std::unique_ptr<Environment>> env =
      MakeEnvironment(run.config.training().env(), EnvOptionsOf(run.config));
  if (!env.ok()) return env.status();
  // Before the run directory exists: networks that cannot be built for the
  // environment's observations would leave an empty run behind.
  if (absl::Status status =
          CheckNetworkConfig(run.plan.learner.network, (*env)->spec());
      !status.ok()) {
    return status;
  }
  if (run.plan.recording.run_dir.empty()) return absl::OkStatus();
  if (run.plan.recording.resume)
    return RunDirectory::Open(run.plan.recording.run_dir).status();
  if (run.start_over) return absl::OkStatus();
  return RunDirectory::CheckFree(run.plan.recording.run_dir);
}

absl::Status PrepareRunDirectory(const ResolvedRun& run) {
  if (!run.start_over) return absl::OkStatus();
  std::fprintf(stderr,
               "vantage: %s holds this run without a checkpoint; starting it "
               "over\n",
               run.plan.recording.run_dir.c_str());
  return RunDirectory::Clear(run.plan.recording.run_dir);
}

Command TrainCommand() {
  Command command;
  command.name = "train";
  command.summary =
      "train on this machine: a learner and actor processes, "
      "or one process";
  command.usage = "vantage train [flags]";
  command.description =
      "Trains one run: by default the distributed main job (a learner and\n"
      "--actors actor processes over loopback gRPC, restarted from the run's\n"
      "checkpoints when one dies), or with --mode=local one process. With\n"
      "--run_dir the run keeps config.json, progress.csv and checkpoints\n"
      "there, and --resume=DIR continues it. The learner's limits\n"
      "(--max_live_actors ...) pass on to the learners it starts. Ends with\n"
      "a line `RESULT train ... mean_return=R` (the last 100 episodes).";
  command.flags = RunFlagNames(/*with_mode=*/true);
  command.declared_flags = RunSettingFlags();
  for (const std::string& name : SecurityFlagNames()) {
    command.flags.push_back(name);
  }
  command.flags.push_back("metrics");
  for (const std::string& name : LearnerLimitFlagNames()) {
    command.flags.push_back(name);
  }
  command.defaults = RunFlagDefaults(/*with_mode=*/true);
  command.example =
      "vantage train --env=Hopper --algo=ppo --estimator=max --rho=0.3 "
      "--steps=1000000 --run_dir=runs/hopper-max";
  command.run = RunTrain;
  return command;
}

}  // namespace vantage
