#include "deploy/cli/learner_command.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <thread>

#include "absl/flags/flag.h"
#include "absl/strings/str_cat.h"
#include "actor/envs/env_registry.h"
#include "common/nn/compute_threads.h"
#include "deploy/cli/learner_limit_flags.h"
#include "deploy/cli/run_flags.h"
#include "deploy/cli/security_flags.h"
#include "deploy/cli/shared_flags.h"
#include "deploy/cli/stop_signal.h"
#include "deploy/cli/train_command.h"
#include "deploy/run/run_config.h"
#include "deploy/run/run_evaluation.h"
#include "learner/server/learner_server.h"
#include "learner/service/actor_gateway.h"

ABSL_FLAG(std::string, listen, "127.0.0.1:0",
          "HOST:PORT to serve actors on (port 0: a free one)");
ABSL_FLAG(std::string, port_file, "", "write the bound port here once serving");
ABSL_FLAG(int, rank, 0,
          "this learner's rank among the run's --learners (rank 0 serves the "
          "rendezvous and writes the run directory)");
ABSL_FLAG(int, world_size, 0,
          "the number of data-parallel learners (the same as --learners; "
          "0: --learners)");
ABSL_FLAG(std::string, rendezvous, "",
          "HOST:PORT of rank 0's rendezvous store, the same for every "
          "learner (needed with more than one)");
ABSL_FLAG(double, replica_timeout_s,
          absl::ToDoubleSeconds(vantage::ReplicaGroupConfig().timeout),
          "how long a learner waits for the others (to join, or in an "
          "update) before it fails");
namespace vantage {
namespace {

int Fail(int code, absl::string_view message) {
  return CommandFailure("learner", code, std::string(message));
}

// --learner_threads, or the machine's cores over the run's learners.
int LearnerThreads(const pb::DistributedSettings& distributed) {
  if (distributed.learner_threads() > 0) return distributed.learner_threads();
  const int cores =
      std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  return std::max(1, cores / std::max(1, distributed.learners()));
}

// The run a learner serves, from its flags: always a distributed one, with
// --world_size standing for --learners. An error is a usage line.
absl::StatusOr<ResolvedRun> ResolveLearnerRun() {
  absl::StatusOr<RunRequest> request = RunRequestFromFlags();
  if (!request.ok()) return request.status();
  // A learner is the distributed run's, whatever a config file says.
  if (request->resume.empty()) request->flags.set_mode("distributed");
  if (const int world_size = absl::GetFlag(FLAGS_world_size); world_size != 0) {
    pb::DistributedSettings& d = *request->flags.mutable_distributed();
    if (d.has_learners() && d.learners() != world_size) {
      return absl::InvalidArgumentError(
          absl::StrCat("--world_size=", world_size,
                       " contradicts --learners=", d.learners()));
    }
    if (request->resume.empty()) d.set_learners(world_size);
  }
  absl::StatusOr<ResolvedRun> resolved = ResolveRunRequest(*request);
  if (!resolved.ok()) return resolved.status();
  if (resolved->config.mode() != "distributed") {
    return absl::InvalidArgumentError(absl::StrCat(
        request->resume,
        " holds a local run; continue it with `vantage train --resume=",
        request->resume, "`"));
  }
  if (absl::Status status = CheckRunCanStart(*resolved); !status.ok()) {
    return status;
  }
  return resolved;
}

// The server's settings from the resolved run and the learner's own flags
// (limits, security, ports, replicas). An error is a usage line.
absl::Status DescribeServer(const ResolvedRun& resolved,
                            LearnerServerConfig& server) {
  if (absl::Status status = ReadLearnerLimits(server); !status.ok()) {
    return status;
  }
  absl::StatusOr<SecurityOptions> security = SecurityFromFlags(/*server=*/true);
  if (!security.ok()) return security.status();
  // The learner's own configuration pins the environment; no actor's
  // registration decides it.
  absl::StatusOr<std::unique_ptr<Environment>> env = MakeEnvironment(
      resolved.config.training().env(), EnvOptionsOf(resolved.config));
  if (!env.ok()) return env.status();
  server.learner = resolved.plan.learner;
  server.recording = resolved.plan.recording;
  server.run_config = resolved.config;
  server.spec = (*env)->spec();
  // Only its spec is needed: a Python env is closed again here.
  env->reset();
  server.listen = absl::GetFlag(FLAGS_listen);
  server.port_file = absl::GetFlag(FLAGS_port_file);
  server.security = *std::move(security);
  server.metrics_address = absl::GetFlag(FLAGS_metrics);
  server.metrics_port_file = absl::GetFlag(FLAGS_metrics_port_file);
  if (resolved.plan.evaluation.enabled()) {
    absl::StatusOr<EvaluatePolicy> evaluate =
        MakeRunEvaluation(resolved.plan.actor, resolved.plan.evaluation);
    if (!evaluate.ok()) return evaluate.status();
    server.eval_every = resolved.plan.evaluation.every;
    server.evaluate = *std::move(evaluate);
  }
  server.replicas.rank = absl::GetFlag(FLAGS_rank);
  server.replicas.world_size = resolved.config.distributed().learners();
  server.replicas.rendezvous = absl::GetFlag(FLAGS_rendezvous);
  server.replicas.timeout =
      absl::Seconds(absl::GetFlag(FLAGS_replica_timeout_s));
  if (absl::Status status = server.replicas.Validate(); !status.ok()) {
    return absl::InvalidArgumentError(
        absl::StrCat(status.message(),
                     " (--rank, --learners, --rendezvous, "
                     "--replica_timeout_s)"));
  }
  return absl::OkStatus();
}

// Serves until the run is done or stopped; rank 0 reports each update and
// the result, the other replicas train silently.
int Serve(const ResolvedRun& resolved, const LearnerServerConfig& server) {
  const bool primary = server.replicas.rank == 0;
  ProgressRow last;
  last.mean_return = std::nan("");
  bool updated = false;
  const absl::Status status =
      RunLearnerServer(server, StopRequested(), [&](const ProgressRow& row) {
        last = row;
        updated = true;
        if (!primary) return;
        std::fprintf(stderr,
                     "learner: update %ld steps %ld return(last100) %.1f "
                     "%.0f steps/s\n",
                     static_cast<long>(row.stats.policy_version),
                     static_cast<long>(row.stats.env_steps), row.mean_return,
                     row.steps_per_second);
      });
  if (!status.ok()) return Fail(kRuntimeError, status.message());
  if (!primary) return 0;
  if (!updated && resolved.plan.recording.resume && !StopRequested()) {
    PrintFinishedAlready(resolved);
    return 0;
  }
  PrintTrainResult(resolved.config, last);
  return 0;
}

int RunLearner(const std::vector<std::string>&) {
  absl::StatusOr<ResolvedRun> resolved = ResolveLearnerRun();
  if (!resolved.ok()) return Fail(kUsageError, resolved.status().message());
  if (absl::Status status = PrepareRunDirectory(*resolved); !status.ok()) {
    return Fail(kRuntimeError, status.message());
  }
  // Before anything computes (the environment is made below).
  SetComputeThreads(LearnerThreads(resolved->config.distributed()));
  LearnerServerConfig server;
  if (absl::Status status = DescribeServer(*resolved, server); !status.ok()) {
    return Fail(kUsageError, status.message());
  }
  return Serve(*resolved, server);
}

}  // namespace

Command LearnerCommand() {
  Command command;
  command.name = "learner";
  command.summary = "serve actors over gRPC and train on their segments";
  command.usage = "vantage learner [flags]";
  command.description =
      "The learner of a distributed run: registers actors (`vantage actor`),\n"
      "trains on the segments they stream and publishes every new policy\n"
      "version, until --steps are done or SIGINT/SIGTERM (which writes a\n"
      "last checkpoint). It takes the run's settings like `vantage train`\n"
      "(its batch is --actors x --envs_per_actor rollouts) and pins the\n"
      "environment: actors must register exactly its spec. The limits bound\n"
      "what clients can make it hold (docs/security.md).";
  command.flags = RunFlagNames(/*with_mode=*/false);
  command.declared_flags = RunSettingFlags();
  for (const char* name :
       {"listen", "port_file", "metrics", "metrics_port_file", "rank",
        "world_size", "rendezvous", "replica_timeout_s"}) {
    command.flags.push_back(name);
  }
  for (const std::string& name : LearnerLimitFlagNames()) {
    command.flags.push_back(name);
  }
  for (const std::string& name : SecurityFlagNames()) {
    command.flags.push_back(name);
  }
  command.defaults = RunFlagDefaults(/*with_mode=*/false);
  command.example =
      "vantage learner --env=HalfCheetah --actors=4 --envs_per_actor=8 "
      "--listen=0.0.0.0:50051 --auth_token_file=token --run_dir=runs/hc";
  command.run = RunLearner;
  return command;
}

}  // namespace vantage
