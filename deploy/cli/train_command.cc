#include "deploy/cli/train_command.h"

#include <ATen/Parallel.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "actor/envs/env_registry.h"
#include "deploy/cli/stop_signal.h"
#include "deploy/launcher.h"
#include "deploy/learner_server.h"
#include "deploy/local_training.h"
#include "deploy/run_config.h"
#include "deploy/run_directory.h"

namespace vantage {
namespace {

int Fail(absl::string_view message) {
  std::fprintf(stderr, "vantage train: %s\n", std::string(message).c_str());
  return 2;
}

// The given config file (if any) with the command line's flags on top.
absl::StatusOr<pb::RunConfig> MergeFlags(const TrainRequest& request) {
  pb::RunConfig config;
  if (!request.config_file.empty()) {
    absl::StatusOr<pb::RunConfig> file = ReadRunConfigFile(request.config_file);
    if (!file.ok()) return file.status();
    config = *file;
  }
  // A repeated field given as a flag replaces the file's list.
  if (request.flags.ensemble_size() > 0) config.clear_ensemble();
  if (request.flags.hidden_size() > 0) config.clear_hidden();
  config.MergeFrom(request.flags);
  return config;
}

// Resuming continues the run exactly as configured; flags that would change
// it are refused rather than silently ignored.
absl::Status CheckNoOverrides(const pb::RunConfig& flags) {
  std::vector<std::string> given;
  const auto* descriptor = flags.GetDescriptor();
  const auto* reflection = flags.GetReflection();
  for (int i = 0; i < descriptor->field_count(); ++i) {
    const auto* field = descriptor->field(i);
    if (field->is_repeated() ? reflection->FieldSize(flags, field) > 0
                             : reflection->HasField(flags, field)) {
      given.push_back(absl::StrCat("--", field->name()));
    }
  }
  if (given.empty()) return absl::OkStatus();
  return absl::InvalidArgumentError(
      absl::StrCat("--resume continues the run as its config.json says; drop ",
                   absl::StrJoin(given, ", ")));
}

std::string Duration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "?";
  const long s = std::lround(seconds);
  return s >= 3600 ? absl::StrCat(s / 3600, "h", (s % 3600) / 60, "m")
                   : absl::StrCat(s / 60, "m", s % 60, "s");
}

}  // namespace

namespace {

struct ResolvedRun {
  pb::RunConfig config;
  LocalTrainingConfig local;
};

absl::StatusOr<ResolvedRun> ResolveRequest(const TrainRequest& request) {
  pb::RunConfig given;
  if (!request.resume.empty()) {
    if (!request.config_file.empty() || !request.run_dir.empty()) {
      return absl::InvalidArgumentError(
          "--resume takes the run directory's own config; drop --config and "
          "--run_dir");
    }
    if (absl::Status status = CheckNoOverrides(request.flags); !status.ok()) {
      return status;
    }
    absl::StatusOr<pb::RunConfig> saved =
        ReadRunConfigFile(request.resume + "/config.json");
    if (!saved.ok()) return saved.status();
    given = *saved;
  } else {
    absl::StatusOr<pb::RunConfig> merged = MergeFlags(request);
    if (!merged.ok()) return merged.status();
    given = *merged;
  }
  absl::StatusOr<pb::RunConfig> config = ResolveRunConfig(given);
  if (!config.ok()) return config.status();
  ResolvedRun run;
  run.config = *config;
  run.local = ToLocalTrainingConfig(*config);
  run.local.config_json = RunConfigToJson(*config);
  run.local.run_dir = request.resume.empty() ? request.run_dir : request.resume;
  run.local.resume = !request.resume.empty();
  run.local.checkpoint_every = config->checkpoint_every();
  run.local.keep_checkpoints = config->keep_checkpoints();
  return run;
}

void PrintResult(const pb::RunConfig& config, const ProgressRow& last) {
  std::printf(
      "RESULT train env=%s algo=%s estimator=%s rho=%g steps=%ld "
      "mean_return=%.1f elapsed_s=%.1f sps=%.0f\n",
      config.env().c_str(), config.algo().c_str(), config.estimator().c_str(),
      config.rho(), static_cast<long>(last.stats.env_steps), last.mean_return,
      last.elapsed_seconds, last.steps_per_second);
}

// One learner and --actors actor processes (deploy/launcher.h).
int RunDistributed(const TrainRequest& request, const ResolvedRun& run) {
  // What the child processes would each refuse, refused once here.
  if (absl::StatusOr<std::unique_ptr<Environment>> env =
          MakeEnvironment(run.config.env());
      !env.ok()) {
    return Fail(env.status().message());
  }
  if (!run.local.resume && !run.local.run_dir.empty()) {
    if (absl::Status status = RunDirectory::CheckFree(run.local.run_dir);
        !status.ok()) {
      return Fail(status.message());
    }
  }
  LaunchConfig launch;
  launch.resume = run.local.resume;
  launch.run_config = run.config;
  launch.run_dir = run.local.run_dir;
  launch.work_dir =
      run.local.run_dir.empty()
          ? absl::StrCat(std::filesystem::temp_directory_path().string(),
                         "/vantage-launch-", ::getpid())
          : run.local.run_dir + "/launch";
  launch.auth_token_file = request.auth_token_file;
  launch.tls_cert = request.tls_cert;
  launch.tls_key = request.tls_key;
  launch.tls_ca = request.tls_ca;
  std::printf(
      "%s %s with %s, estimator %s (rho %g), %ld steps, seed %lu: "
      "1 learner + %d actors x %d envs over gRPC%s%s\n",
      run.local.resume ? "resuming" : "training", run.config.env().c_str(),
      run.config.algo().c_str(), run.config.estimator().c_str(),
      run.config.rho(), static_cast<long>(run.config.steps()),
      static_cast<unsigned long>(run.config.seed()), run.config.actors(),
      run.config.envs_per_actor(),
      run.local.run_dir.empty() ? "" : ", run directory ",
      run.local.run_dir.c_str());
  std::fflush(stdout);
  const absl::Status status = RunDistributedTraining(launch, StopRequested());
  if (run.local.run_dir.empty()) {
    std::error_code error;
    std::filesystem::remove_all(launch.work_dir, error);
  }
  if (!status.ok()) return Fail(status.message());
  return 0;
}

}  // namespace

int RunLearnerCommand(const LearnerRequest& request) {
  absl::StatusOr<ResolvedRun> resolved = ResolveRequest(request.train);
  if (!resolved.ok()) return Fail(resolved.status().message());
  at::set_num_threads(1);
  // The learner's own configuration pins the environment; no actor's
  // registration decides it.
  absl::StatusOr<std::unique_ptr<Environment>> env =
      MakeEnvironment(resolved->config.env());
  if (!env.ok()) return Fail(env.status().message());
  LearnerServerConfig server;
  server.training = resolved->local;
  server.run_config = resolved->config;
  server.spec = (*env)->spec();
  server.limits = request.limits;
  server.service_limits = request.service_limits;
  server.max_server_threads = request.max_server_threads;
  server.max_grpc_memory_bytes = request.max_grpc_memory_bytes;
  server.listen = request.listen;
  server.port_file = request.port_file;
  server.security = request.security;
  server.metrics_address = request.metrics;
  ProgressRow last;
  last.mean_return = std::nan("");
  const absl::Status status =
      RunLearnerServer(server, StopRequested(), [&](const ProgressRow& row) {
        last = row;
        std::fprintf(stderr,
                     "learner: update %ld steps %ld return(last100) %.1f "
                     "%.0f steps/s\n",
                     static_cast<long>(row.stats.policy_version),
                     static_cast<long>(row.stats.env_steps), row.mean_return,
                     row.steps_per_second);
      });
  if (!status.ok()) return Fail(status.message());
  PrintResult(resolved->config, last);
  return 0;
}

int RunTrainCommand(const TrainRequest& request) {
  absl::StatusOr<ResolvedRun> resolved = ResolveRequest(request);
  if (!resolved.ok()) return Fail(resolved.status().message());
  const pb::RunConfig* config = &resolved->config;
  const LocalTrainingConfig& local = resolved->local;
  if (config->mode() == "distributed")
    return RunDistributed(request, *resolved);

  at::set_num_threads(1);
  std::printf(
      "%s %s with %s, estimator %s (rho %g, ensemble %s), %ld steps, seed "
      "%lu%s%s\n",
      local.resume ? "resuming" : "training", config->env().c_str(),
      config->algo().c_str(), config->estimator().c_str(), config->rho(),
      absl::StrJoin(config->ensemble(), ",").c_str(),
      static_cast<long>(config->steps()),
      static_cast<unsigned long>(config->seed()),
      local.run_dir.empty() ? "" : ", run directory ", local.run_dir.c_str());
  std::fflush(stdout);
  const bool terminal = ::isatty(STDOUT_FILENO) == 1;
  ProgressRow last;
  last.mean_return = std::nan("");
  const absl::Status status =
      RunLocalTraining(local, [&](const ProgressRow& progress) {
        last = progress;
        if (!terminal) return true;
        const double remaining = (config->steps() - progress.stats.env_steps) /
                                 progress.steps_per_second;
        std::printf(
            "\r\033[Kupdate %ld  steps %ld/%ld  %.0f steps/s  "
            "return(last100) %.1f  ETA %s",
            static_cast<long>(progress.stats.policy_version),
            static_cast<long>(progress.stats.env_steps),
            static_cast<long>(config->steps()), progress.steps_per_second,
            progress.mean_return, Duration(remaining).c_str());
        std::fflush(stdout);
        return true;
      });
  if (terminal) std::printf("\n");
  if (!status.ok()) return Fail(status.message());
  PrintResult(*config, last);
  return 0;
}

}  // namespace vantage
