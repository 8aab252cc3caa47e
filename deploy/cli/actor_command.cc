#include "deploy/cli/actor_command.h"

#include <cstdio>
#include <string>

#include "absl/flags/flag.h"
#include "absl/strings/str_cat.h"
#include "actor/remote/remote_actor.h"
#include "common/nn/compute_threads.h"
#include "deploy/cli/command_line.h"
#include "deploy/cli/security_flags.h"
#include "deploy/cli/shared_flags.h"
#include "deploy/cli/stop_signal.h"

ABSL_FLAG(std::string, name, vantage::RemoteActorConfig().name,
          "a name for logs");
ABSL_FLAG(int, max_reconnects, vantage::RemoteActorConfig().max_reconnects,
          "reconnection attempts (0: exit at the first failure, -1: forever)");

namespace vantage {
namespace {

int Fail(int code, absl::string_view message) {
  return CommandFailure("actor", code, std::string(message));
}

int RunActor(const std::vector<std::string>&) {
  RemoteActorConfig config;
  config.learner = absl::GetFlag(FLAGS_learner);
  if (FlagGiven("env")) config.env = absl::GetFlag(FLAGS_env);
  config.env_kwargs = absl::GetFlag(FLAGS_env_kwargs);
  config.num_envs = absl::GetFlag(FLAGS_envs);
  if (FlagGiven("seed")) config.seed = absl::GetFlag(FLAGS_seed);
  config.name = absl::GetFlag(FLAGS_name);
  config.max_reconnects = absl::GetFlag(FLAGS_max_reconnects);
  config.metrics_address = absl::GetFlag(FLAGS_metrics);
  config.metrics_port_file = absl::GetFlag(FLAGS_metrics_port_file);
  if (config.num_envs < 1 || config.learner.empty()) {
    return Fail(kUsageError,
                "--learner=HOST:PORT and --envs >= 1 are required");
  }
  absl::StatusOr<SecurityOptions> security =
      SecurityFromFlags(/*server=*/false);
  if (!security.ok()) return Fail(kUsageError, security.status().message());
  config.security = *std::move(security);
  // One intra-op thread per actor: actors are many processes already.
  SetComputeThreads(1);
  const absl::Status status = RunRemoteActor(config, StopRequested());
  if (!status.ok()) return Fail(kRuntimeError, status.message());
  return 0;
}

}  // namespace

Command ActorCommand() {
  Command command;
  command.name = "actor";
  command.summary = "act in environments and stream segments to a learner";
  command.usage = "vantage actor --learner=HOST:PORT [flags]";
  command.description =
      "Registers with a learner, steps --envs environments with the newest\n"
      "policy and streams trajectory segments to it, reconnecting with\n"
      "backoff when the learner goes away (its environments kept). Ends at\n"
      "SIGINT/SIGTERM (exit 0) or when the learner refuses it or the\n"
      "reconnects run out (exit 1). Without --seed its environments' seed\n"
      "comes from the run's seed and the actor id the learner assigns, so\n"
      "actors started alike (a Deployment's pods) reset differently.";
  command.flags = {"learner",       "env",  "env_kwargs", "envs",
                   "seed",          "name", "metrics",    "metrics_port_file",
                   "max_reconnects"};
  for (const std::string& name : SecurityFlagNames()) {
    command.flags.push_back(name);
  }
  command.defaults = {{"env", RemoteActorConfig().env}};
  command.example =
      "vantage actor --learner=10.0.0.5:50051 --env=HalfCheetah --envs=8 "
      "--auth_token_file=token";
  command.run = RunActor;
  return command;
}

}  // namespace vantage
