#include "deploy/cli/learner_limit_flags.h"

#include "absl/flags/commandlineflag.h"
#include "absl/flags/flag.h"
#include "absl/flags/reflection.h"
#include "absl/time/time.h"
#include "deploy/cli/command_line.h"
#include "learner/server/learner_server.h"
#include "learner/service/actor_gateway.h"
#include "learner/service/learner_service.h"

// What clients can make a learner hold; defaults from the structs that use
// them (docs/security.md explains each).
ABSL_FLAG(int64_t, max_live_actors, vantage::GatewayLimits().max_live_actors,
          "registrations held at once (more: RESOURCE_EXHAUSTED)");
ABSL_FLAG(int64_t, max_envs_per_actor,
          vantage::GatewayLimits().max_envs_per_actor,
          "env slots one registration may claim");
ABSL_FLAG(int64_t, max_live_env_slots,
          vantage::GatewayLimits().max_live_env_slots,
          "env slots over all live registrations");
ABSL_FLAG(double, actor_expiry_s,
          absl::ToDoubleSeconds(vantage::GatewayLimits().actor_expiry),
          "a registration with no open call for this long expires");
ABSL_FLAG(double, claim_timeout_s,
          absl::ToDoubleSeconds(vantage::GatewayLimits().claim_timeout),
          "a registration that opens no call within this expires");
ABSL_FLAG(int64_t, max_unclaimed_per_peer,
          vantage::GatewayLimits().max_unclaimed_per_peer,
          "registrations one host may hold before opening a call");
ABSL_FLAG(double, idle_stream_timeout_s,
          absl::ToDoubleSeconds(vantage::ServiceLimits().idle_stream_timeout),
          "a segment stream silent for this long is cancelled");
ABSL_FLAG(double, max_abs_observation,
          vantage::ValueLimits().max_abs_observation,
          "segments with a larger |observation| are refused");
ABSL_FLAG(double, max_abs_action, vantage::ValueLimits().max_abs_action,
          "segments with a larger |action| are refused");
ABSL_FLAG(double, max_abs_reward, vantage::ValueLimits().max_abs_reward,
          "segments with a larger |reward| are refused");
ABSL_FLAG(double, max_abs_log_prob, vantage::ValueLimits().max_abs_log_prob,
          "segments with a larger |behaviour log-prob| are refused");
ABSL_FLAG(int, max_server_threads,
          vantage::LearnerServerConfig().max_server_threads,
          "gRPC server threads (each open call holds one)");
ABSL_FLAG(int64_t, max_grpc_memory_mb,
          vantage::LearnerServerConfig().max_grpc_memory_bytes >> 20,
          "memory gRPC may use for its buffers, MiB");

namespace vantage {

std::vector<std::string> LearnerLimitFlagNames() {
  return {
      "max_live_actors",       "max_envs_per_actor",  "max_live_env_slots",
      "actor_expiry_s",        "claim_timeout_s",     "max_unclaimed_per_peer",
      "idle_stream_timeout_s", "max_abs_observation", "max_abs_action",
      "max_abs_reward",        "max_abs_log_prob",    "max_server_threads",
      "max_grpc_memory_mb"};
}

absl::Status ReadLearnerLimits(LearnerServerConfig& server) {
  GatewayLimits& limits = server.limits;
  limits.max_live_actors = absl::GetFlag(FLAGS_max_live_actors);
  limits.max_envs_per_actor = absl::GetFlag(FLAGS_max_envs_per_actor);
  limits.max_live_env_slots = absl::GetFlag(FLAGS_max_live_env_slots);
  limits.actor_expiry = absl::Seconds(absl::GetFlag(FLAGS_actor_expiry_s));
  limits.claim_timeout = absl::Seconds(absl::GetFlag(FLAGS_claim_timeout_s));
  limits.max_unclaimed_per_peer = absl::GetFlag(FLAGS_max_unclaimed_per_peer);
  limits.values.max_abs_observation = absl::GetFlag(FLAGS_max_abs_observation);
  limits.values.max_abs_action = absl::GetFlag(FLAGS_max_abs_action);
  limits.values.max_abs_reward = absl::GetFlag(FLAGS_max_abs_reward);
  limits.values.max_abs_log_prob = absl::GetFlag(FLAGS_max_abs_log_prob);
  server.service_limits.idle_stream_timeout =
      absl::Seconds(absl::GetFlag(FLAGS_idle_stream_timeout_s));
  server.max_server_threads = absl::GetFlag(FLAGS_max_server_threads);
  server.max_grpc_memory_bytes = absl::GetFlag(FLAGS_max_grpc_memory_mb) << 20;
  if (absl::Status status = limits.Validate(); !status.ok()) return status;
  if (!(server.service_limits.idle_stream_timeout > absl::ZeroDuration())) {
    return absl::InvalidArgumentError("--idle_stream_timeout_s must be > 0");
  }
  if (server.max_server_threads < 8) {
    return absl::InvalidArgumentError("--max_server_threads must be >= 8");
  }
  if (absl::GetFlag(FLAGS_max_grpc_memory_mb) < 1) {
    return absl::InvalidArgumentError("--max_grpc_memory_mb must be >= 1");
  }
  return absl::OkStatus();
}

absl::Status CheckLearnerLimits() {
  LearnerServerConfig checked;
  return ReadLearnerLimits(checked);
}

std::vector<std::string> GivenLearnerLimitArgs() {
  std::vector<std::string> args;
  for (const std::string& name : LearnerLimitFlagNames()) {
    if (!FlagGiven(name)) continue;
    const absl::CommandLineFlag* flag = absl::FindCommandLineFlag(name);
    args.push_back("--" + name + "=" + flag->CurrentValue());
  }
  return args;
}

}  // namespace vantage
