#include "deploy/cli/run_flags.h"

#include <google/protobuf/descriptor.h>
#include <google/protobuf/message.h>

#include "absl/flags/flag.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "deploy/cli/command_line.h"
#include "deploy/cli/shared_flags.h"
#include "deploy/run_config.h"
#include "learner/algorithms/algorithm.h"

// Every default is ResolveRunConfig's (see RunFlagDefaults): a flag's own
// default below is never read, since only given flags enter the config.
ABSL_FLAG(std::string, mode, "",
          "distributed (a learner and --actors actor processes over gRPC on "
          "this machine) | local (one process)");
ABSL_FLAG(int, actors, 0, "distributed: actor processes");
ABSL_FLAG(int, envs_per_actor, 0, "distributed: environments per actor");
ABSL_FLAG(std::string, algo, "", "ppo | a2c | trpo");
ABSL_FLAG(std::string, estimator, "",
          "the biased statistic: gae (none) | max | min | maxabs | order:D");
ABSL_FLAG(double, rho, 0, "probability of the biased estimate per sample");
ABSL_FLAG(std::vector<std::string>, ensemble, {},
          "the path ensemble's k-step lengths, comma-separated");
ABSL_FLAG(int64_t, steps, 0, "environment steps of the run");
ABSL_FLAG(int64_t, horizon, 0, "rollout length per environment and update");
ABSL_FLAG(int, minibatches, 0,
          "ppo: minibatches per epoch; a2c: n of the paper's 5n trick "
          "(5n-step rollouts updated as n 5-step minibatches)");
ABSL_FLAG(int, epochs, 0, "ppo: epochs per update");
ABSL_FLAG(double, learning_rate, 0,
          "ppo: Adam, a2c: RMSProp (both decayed linearly), trpo: the value "
          "function's Adam");
ABSL_FLAG(double, gamma, 0, "discount");
ABSL_FLAG(double, gae_lambda, 0, "GAE lambda");
ABSL_FLAG(double, entropy_coef, 0, "entropy bonus coefficient");
ABSL_FLAG(std::vector<std::string>, hidden, {},
          "hidden layer sizes of the policy and value networks");
ABSL_FLAG(bool, scale_rewards, false,
          "divide rewards by the running std of discounted returns");
ABSL_FLAG(double, max_kl, 0, "trpo: the trust region's KL bound");
ABSL_FLAG(int, checkpoint_every, 0,
          "updates between checkpoints (with --run_dir)");
ABSL_FLAG(int, keep_checkpoints, 0, "newest checkpoints kept");
ABSL_FLAG(bool, sync, true,
          "each batch only from the current policy version (actors wait for "
          "it); --nosync: asynchronous within --max_policy_lag");
ABSL_FLAG(int64_t, max_policy_lag, 0,
          "asynchronous: segments older than this many versions are dropped "
          "and counted");
ABSL_FLAG(int64_t, segment_length, 0,
          "steps per segment an actor sends (divides --horizon with --sync)");
ABSL_FLAG(std::string, config, "",
          "a JSON run config (as a run directory's config.json); the flags "
          "given override it");
ABSL_FLAG(std::string, run_dir, "",
          "directory for config.json, progress.csv and checkpoints/");
ABSL_FLAG(std::string, resume, "",
          "continue the run in this directory from its newest checkpoint");

namespace vantage {
namespace {

using google::protobuf::FieldDescriptor;

// Appends the integers of a list flag; an entry that is none is an error.
template <typename Repeated>
absl::Status ParseIntegers(const char* name,
                           const std::vector<std::string>& values,
                           Repeated& out) {
  for (const std::string& text : values) {
    int64_t value = 0;
    if (!absl::SimpleAtoi(text, &value)) {
      return absl::InvalidArgumentError(
          absl::StrCat("--", name, " entry '", text, "' is not an integer"));
    }
    out.Add(value);
  }
  return absl::OkStatus();
}

std::string RunConfigFieldTextOf(const pb::RunConfig& config,
                                 const FieldDescriptor& field) {
  const auto* reflection = config.GetReflection();
  if (field.is_repeated()) {
    std::vector<std::string> values;
    for (int i = 0; i < reflection->FieldSize(config, &field); ++i) {
      values.push_back(
          absl::StrCat(reflection->GetRepeatedInt64(config, &field, i)));
    }
    return absl::StrJoin(values, ",");
  }
  if (!reflection->HasField(config, &field)) return "";
  switch (field.cpp_type()) {
    case FieldDescriptor::CPPTYPE_STRING:
      return reflection->GetString(config, &field);
    case FieldDescriptor::CPPTYPE_BOOL:
      return reflection->GetBool(config, &field) ? "true" : "false";
    case FieldDescriptor::CPPTYPE_DOUBLE:
      return absl::StrFormat("%g", reflection->GetDouble(config, &field));
    case FieldDescriptor::CPPTYPE_INT32:
      return absl::StrCat(reflection->GetInt32(config, &field));
    case FieldDescriptor::CPPTYPE_INT64:
      return absl::StrCat(reflection->GetInt64(config, &field));
    case FieldDescriptor::CPPTYPE_UINT64:
      return absl::StrCat(reflection->GetUInt64(config, &field));
    default:
      return "?";
  }
}

pb::RunConfig Resolved(const std::string& algo, const std::string& mode) {
  pb::RunConfig given;
  if (!algo.empty()) given.set_algo(algo);
  if (!mode.empty()) given.set_mode(mode);
  // The defaults resolve by construction; a failure is a programming error
  // that the help test catches as an empty default.
  absl::StatusOr<pb::RunConfig> resolved = ResolveRunConfig(given);
  return resolved.ok() ? *resolved : pb::RunConfig();
}

}  // namespace

std::string RunConfigFieldText(const pb::RunConfig& config,
                               const std::string& name) {
  const FieldDescriptor* field =
      pb::RunConfig::descriptor()->FindFieldByName(name);
  return field == nullptr ? "" : RunConfigFieldTextOf(config, *field);
}

std::vector<std::string> RunFlagNames(bool with_mode) {
  std::vector<std::string> names;
  const auto* descriptor = pb::RunConfig::descriptor();
  for (int i = 0; i < descriptor->field_count(); ++i) {
    const std::string& name = descriptor->field(i)->name();
    if (name != "mode" || with_mode) names.push_back(name);
  }
  for (const char* name : {"config", "run_dir", "resume"}) {
    names.push_back(name);
  }
  return names;
}

std::map<std::string, std::string> RunFlagDefaults(bool with_mode) {
  const pb::RunConfig standard = Resolved("", "");
  const pb::RunConfig local = Resolved("", "local");
  std::map<std::string, std::string> defaults;
  const auto* descriptor = pb::RunConfig::descriptor();
  for (int i = 0; i < descriptor->field_count(); ++i) {
    const FieldDescriptor& field = *descriptor->field(i);
    std::string text = RunConfigFieldTextOf(standard, field);
    defaults[field.name()] = text;
    // Varying a flag shows nothing about its own default.
    if (field.name() == "algo" || field.name() == "mode") continue;
    std::vector<std::string> by_algorithm;
    bool differs = false;
    for (const std::string& algo : AlgorithmNames()) {
      const std::string value = RunConfigFieldTextOf(Resolved(algo, ""), field);
      differs = differs || value != text;
      by_algorithm.push_back(absl::StrCat(algo, ": ", value));
    }
    if (differs) text = absl::StrJoin(by_algorithm, "; ");
    const std::string in_local = RunConfigFieldTextOf(local, field);
    if (with_mode && in_local != RunConfigFieldTextOf(standard, field)) {
      absl::StrAppend(&text, " (--mode=local: ",
                      in_local.empty() ? "unused" : in_local, ")");
    }
    defaults[field.name()] = text;
  }
  return defaults;
}

absl::StatusOr<RunRequest> RunRequestFromFlags() {
  RunRequest request;
  pb::RunConfig& c = request.flags;
  if (FlagGiven("mode")) c.set_mode(absl::GetFlag(FLAGS_mode));
  if (FlagGiven("env")) c.set_env(absl::GetFlag(FLAGS_env));
  if (FlagGiven("algo")) c.set_algo(absl::GetFlag(FLAGS_algo));
  if (FlagGiven("estimator")) c.set_estimator(absl::GetFlag(FLAGS_estimator));
  if (FlagGiven("rho")) c.set_rho(absl::GetFlag(FLAGS_rho));
  if (FlagGiven("ensemble")) {
    if (absl::Status status = ParseIntegers(
            "ensemble", absl::GetFlag(FLAGS_ensemble), *c.mutable_ensemble());
        !status.ok()) {
      return status;
    }
  }
  if (FlagGiven("steps")) c.set_steps(absl::GetFlag(FLAGS_steps));
  if (FlagGiven("seed")) c.set_seed(absl::GetFlag(FLAGS_seed));
  if (FlagGiven("envs")) c.set_envs(absl::GetFlag(FLAGS_envs));
  if (FlagGiven("horizon")) c.set_horizon(absl::GetFlag(FLAGS_horizon));
  if (FlagGiven("minibatches")) {
    c.set_minibatches(absl::GetFlag(FLAGS_minibatches));
  }
  if (FlagGiven("epochs")) c.set_epochs(absl::GetFlag(FLAGS_epochs));
  if (FlagGiven("learning_rate")) {
    c.set_learning_rate(absl::GetFlag(FLAGS_learning_rate));
  }
  if (FlagGiven("gamma")) c.set_gamma(absl::GetFlag(FLAGS_gamma));
  if (FlagGiven("gae_lambda")) {
    c.set_gae_lambda(absl::GetFlag(FLAGS_gae_lambda));
  }
  if (FlagGiven("entropy_coef")) {
    c.set_entropy_coef(absl::GetFlag(FLAGS_entropy_coef));
  }
  if (FlagGiven("hidden")) {
    if (absl::Status status = ParseIntegers(
            "hidden", absl::GetFlag(FLAGS_hidden), *c.mutable_hidden());
        !status.ok()) {
      return status;
    }
  }
  if (FlagGiven("scale_rewards")) {
    c.set_scale_rewards(absl::GetFlag(FLAGS_scale_rewards));
  }
  if (FlagGiven("max_kl")) c.set_max_kl(absl::GetFlag(FLAGS_max_kl));
  if (FlagGiven("checkpoint_every")) {
    c.set_checkpoint_every(absl::GetFlag(FLAGS_checkpoint_every));
  }
  if (FlagGiven("keep_checkpoints")) {
    c.set_keep_checkpoints(absl::GetFlag(FLAGS_keep_checkpoints));
  }
  if (FlagGiven("sync")) c.set_sync(absl::GetFlag(FLAGS_sync));
  if (FlagGiven("actors")) c.set_actors(absl::GetFlag(FLAGS_actors));
  if (FlagGiven("envs_per_actor")) {
    c.set_envs_per_actor(absl::GetFlag(FLAGS_envs_per_actor));
  }
  if (FlagGiven("max_policy_lag")) {
    c.set_max_policy_lag(absl::GetFlag(FLAGS_max_policy_lag));
  }
  if (FlagGiven("segment_length")) {
    c.set_segment_length(absl::GetFlag(FLAGS_segment_length));
  }
  request.config_file = absl::GetFlag(FLAGS_config);
  request.run_dir = absl::GetFlag(FLAGS_run_dir);
  request.resume = absl::GetFlag(FLAGS_resume);
  return request;
}

}  // namespace vantage
