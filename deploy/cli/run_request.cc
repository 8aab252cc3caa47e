#include "deploy/cli/run_request.h"

#include <cstdio>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "deploy/run/run_config.h"
#include "learner/algorithms/algorithm_config.h"
#include "learner/checkpoint/checkpoint_files.h"
#include "learner/run/run_directory.h"

namespace vantage {
namespace {

// The given config file (if any) with the given flags on top.
absl::StatusOr<pb::RunConfig> MergeFlags(const RunRequest& request) {
  pb::RunConfig config;
  if (request.config.has_value()) {
    config = *request.config;
  } else if (!request.config_file.empty()) {
    absl::StatusOr<pb::RunConfig> file = ReadRunConfigFile(request.config_file);
    if (!file.ok()) return file.status();
    config = *file;
  }
  const pb::RunConfig& flags = request.flags;
  if (request.algo.empty() &&
      flags.algorithm_case() != pb::RunConfig::ALGORITHM_NOT_SET &&
      config.algorithm_case() != pb::RunConfig::ALGORITHM_NOT_SET &&
      flags.algorithm_case() != config.algorithm_case()) {
    return absl::InvalidArgumentError(absl::StrCat(
        "the flags set ", AlgorithmNameOf(flags), " settings but ",
        request.config_file, " holds ", AlgorithmNameOf(config),
        " settings; add --algo=", AlgorithmNameOf(flags), " to switch"));
  }
  // A repeated field given as a flag replaces the file's list.
  if (flags.training().hidden_size() > 0) {
    config.mutable_training()->clear_hidden();
  }
  if (flags.advantage().ensemble_size() > 0) {
    config.mutable_advantage()->clear_ensemble();
  }
  if (flags.exploration().ex2().hidden_size() > 0) {
    config.mutable_exploration()->mutable_ex2()->clear_hidden();
  }
  config.MergeFrom(flags);
  if (request.exploration == "none") config.clear_exploration();
  return config;
}

// How a run is served, not what it is: the actors the launcher starts and
// how long one may owe segments. A resumed run may change them (its
// learner's pool is elastic); its batch (`--envs`) stays.
bool ServesTheRun(const std::string& flag) {
  return flag == "actors" || flag == "envs_per_actor" ||
         flag == "actor_stall_timeout_s";
}

// Resuming continues the run exactly as configured; flags that would change
// it are refused rather than silently ignored.
absl::Status CheckNoOverrides(const RunRequest& request) {
  std::vector<std::string> given;
  for (const std::string& name : request.given_flags) {
    if (!ServesTheRun(name)) given.push_back(absl::StrCat("--", name));
  }
  if (given.empty()) return absl::OkStatus();
  return absl::InvalidArgumentError(absl::StrCat(
      "--resume continues the run as its config.json says (only --actors, "
      "--envs_per_actor and --actor_stall_timeout_s may change); drop ",
      absl::StrJoin(given, ", ")));
}

// The serving flags given with --resume, over the run's own config.
void ApplyServingFlags(const RunRequest& request, pb::RunConfig& config) {
  const pb::DistributedSettings& given = request.flags.distributed();
  if (!given.has_actors() && !given.has_envs_per_actor() &&
      !given.has_actor_stall_timeout_s()) {
    return;  // a local run has no distributed section to touch
  }
  pb::DistributedSettings& d = *config.mutable_distributed();
  if (given.has_actors()) d.set_actors(given.actors());
  if (given.has_envs_per_actor()) d.set_envs_per_actor(given.envs_per_actor());
  if (given.has_actor_stall_timeout_s()) {
    d.set_actor_stall_timeout_s(given.actor_stall_timeout_s());
  }
}

// --resume_if_exists: what the directory holds decides between starting,
// resuming and starting over; a run with other settings is never touched.
absl::Status ApplyResumeIfExists(const RunRequest& request, ResolvedRun& run) {
  if (request.run_dir.empty() || !request.resume.empty()) {
    return absl::InvalidArgumentError(
        "--resume_if_exists goes with --run_dir (and without --resume)");
  }
  const std::string& dir = request.run_dir;
  absl::StatusOr<RunDirectory> existing = RunDirectory::Open(dir);
  if (!existing.ok()) return absl::OkStatus();  // no run there: start it
  absl::StatusOr<pb::RunConfig> saved =
      ReadRunConfigFile(absl::StrCat(dir, "/config.json"));
  if (!saved.ok()) return saved.status();
  absl::StatusOr<pb::RunConfig> held = ResolveRunConfig(*saved);
  if (!held.ok()) {
    return absl::InvalidArgumentError(
        absl::StrCat(dir, "/config.json holds settings this vantage refuses: ",
                     held.status().message()));
  }
  // How it is served may differ (an elastic pool); nothing else may.
  pb::RunConfig comparable = *held;
  if (comparable.has_distributed() && run.config.has_distributed()) {
    const pb::DistributedSettings& now = run.config.distributed();
    pb::DistributedSettings& d = *comparable.mutable_distributed();
    d.set_actors(now.actors());
    d.set_envs_per_actor(now.envs_per_actor());
    d.set_actor_stall_timeout_s(now.actor_stall_timeout_s());
  }
  if (const std::string difference =
          RunConfigDifference(comparable, run.config);
      !difference.empty()) {
    return absl::InvalidArgumentError(
        absl::StrCat(dir, " holds a run made with other settings (", difference,
                     "); continue it as it is with --resume=", dir,
                     " or choose another --run_dir"));
  }
  if (ListCheckpoints(existing->checkpoint_directory()).empty()) {
    run.start_over = true;
  } else {
    run.plan.recording.resume = true;
  }
  return absl::OkStatus();
}

}  // namespace

absl::StatusOr<ResolvedRun> ResolveRunRequest(const RunRequest& request) {
  pb::RunConfig given;
  if (!request.resume.empty()) {
    if (!request.config_file.empty() || !request.run_dir.empty()) {
      return absl::InvalidArgumentError(
          "--resume takes the run directory's own config; drop --config and "
          "--run_dir");
    }
    if (absl::Status status = CheckNoOverrides(request); !status.ok()) {
      return status;
    }
    absl::StatusOr<pb::RunConfig> saved =
        ReadRunConfigFile(request.resume + "/config.json");
    if (!saved.ok()) return saved.status();
    given = *saved;
    ApplyServingFlags(request, given);
  } else {
    absl::StatusOr<pb::RunConfig> merged = MergeFlags(request);
    if (!merged.ok()) return merged.status();
    given = *merged;
  }
  absl::StatusOr<pb::RunConfig> config = ResolveRunConfig(given);
  if (!config.ok()) return config.status();
  absl::StatusOr<RunPlan> plan = PlanRun(*config);
  if (!plan.ok()) return plan.status();
  ResolvedRun run;
  run.config = *config;
  run.plan = *std::move(plan);
  run.plan.recording.run_dir =
      request.resume.empty() ? request.run_dir : request.resume;
  run.plan.recording.resume = !request.resume.empty();
  if (request.resume_if_exists) {
    if (absl::Status status = ApplyResumeIfExists(request, run); !status.ok()) {
      return status;
    }
  }
  return run;
}

void PrintTrainResult(const pb::RunConfig& config, const ProgressRow& last) {
  std::printf(
      "RESULT train env=%s algo=%s estimator=%s rho=%g steps=%ld "
      "mean_return=%.1f elapsed_s=%.1f sps=%.0f\n",
      config.training().env().c_str(), AlgorithmNameOf(config).c_str(),
      config.advantage().estimator().c_str(), config.advantage().rho(),
      static_cast<long>(last.stats.env_steps), last.mean_return,
      last.elapsed_seconds, last.steps_per_second);
}

void PrintFinishedAlready(const ResolvedRun& run) {
  std::printf("%s is finished already (%ld steps); nothing to do\n",
              run.plan.recording.run_dir.c_str(),
              static_cast<long>(run.config.training().steps()));
}

}  // namespace vantage
