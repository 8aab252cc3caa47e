#include "deploy/run_config.h"

#include <google/protobuf/util/json_util.h>

#include <fstream>
#include <sstream>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "common/advantage/advantage_config.h"
#include "learner/algorithms/algorithm.h"

namespace vantage {
namespace {

absl::Status Invalid(absl::string_view flag, absl::string_view rule) {
  return absl::InvalidArgumentError(absl::StrCat("--", flag, " ", rule));
}

}  // namespace

absl::StatusOr<pb::RunConfig> ResolveRunConfig(const pb::RunConfig& given) {
  pb::RunConfig c = given;
  // The main job is the distributed one; --mode=local keeps one process.
  if (!c.has_mode()) c.set_mode("distributed");
  if (!c.has_env()) c.set_env("InvertedPendulum");
  if (!c.has_algo()) c.set_algo("ppo");
  if (!c.has_estimator()) c.set_estimator("maxabs");
  if (!c.has_rho()) c.set_rho(0.4);
  if (c.ensemble_size() == 0) {
    for (int64_t k : {1, 16, 64, 2048}) c.add_ensemble(k);
  }
  if (!c.has_steps()) c.set_steps(150000);
  if (!c.has_seed()) c.set_seed(0);
  if (c.has_envs() && (c.envs() < 1 || c.envs() > 4096)) {
    return Invalid("envs", "must be in [1, 4096]");
  }
  if (c.mode() == "distributed") {
    // Two actor processes by default; a batch given as --envs alone is
    // split over them (over one actor if it does not split evenly).
    if (!c.has_actors()) {
      const int64_t per_actor = c.has_envs_per_actor() ? c.envs_per_actor() : 0;
      if (c.has_envs() && per_actor > 0) {
        c.set_actors(static_cast<int32_t>(c.envs() / per_actor));
      } else {
        c.set_actors(c.has_envs() && c.envs() % 2 != 0 ? 1 : 2);
      }
    }
    if (!c.has_envs_per_actor()) {
      c.set_envs_per_actor(
          c.has_envs()
              ? static_cast<int32_t>(c.envs() / std::max(1, c.actors()))
              : 1);
    }
    if (c.actors() < 1 || c.actors() > 256) {
      return Invalid("actors", "must be in [1, 256]");
    }
    if (c.envs_per_actor() < 1 || c.envs_per_actor() > 4096) {
      return Invalid("envs_per_actor", "must be in [1, 4096]");
    }
    // At most 256 x 4096: the product fits an int32.
    const int32_t streams = c.actors() * c.envs_per_actor();
    if (streams > 4096) {
      return Invalid("envs_per_actor",
                     absl::StrCat("makes --actors x --envs_per_actor = ",
                                  streams, " streams, more than 4096"));
    }
    // The learner's batch holds one rollout per actor environment.
    if (c.has_envs() && c.envs() != streams) {
      return Invalid("envs",
                     absl::StrCat("is the learner's batch of --actors x "
                                  "--envs_per_actor = ",
                                  streams, " streams in a distributed run"));
    }
    c.set_envs(streams);
  } else {
    c.clear_actors();
    c.clear_envs_per_actor();
  }
  if (!c.has_envs()) c.set_envs(1);
  if (c.mode() != "local" && c.mode() != "distributed") {
    return Invalid("mode:", absl::StrCat("unknown mode '", c.mode(),
                                         "'; available: local, distributed"));
  }
  AlgorithmConfig algorithms;
  algorithms.name = c.algo();
  if (absl::Status status = algorithms.Validate(); !status.ok()) {
    return Invalid("algo:", status.message());
  }
  const bool ppo = c.algo() == "ppo";
  const bool a2c = c.algo() == "a2c";
  if (!c.has_minibatches()) {
    c.set_minibatches(ppo ? algorithms.ppo.minibatches : 4);
  }
  if (c.minibatches() < 1) return Invalid("minibatches", "must be >= 1");
  if (!c.has_horizon()) {
    c.set_horizon(ppo   ? 2048
                  : a2c ? int64_t{algorithms.a2c.steps_per_minibatch} *
                              c.minibatches()
                        : 1024);
  }
  if (!c.has_epochs()) c.set_epochs(algorithms.ppo.epochs);
  if (!c.has_learning_rate()) {
    c.set_learning_rate(ppo   ? algorithms.ppo.learning_rate
                        : a2c ? algorithms.a2c.learning_rate
                              : algorithms.trpo.value_learning_rate);
  }
  if (!c.has_gamma()) c.set_gamma(0.99);
  // The baselines' choices: GAE 0.95 for PPO, 0.98 for TRPO, plain n-step
  // returns (lambda 1) for A2C.
  if (!c.has_gae_lambda()) c.set_gae_lambda(ppo ? 0.95 : a2c ? 1.0 : 0.98);
  if (!c.has_entropy_coef()) {
    c.set_entropy_coef(a2c ? algorithms.a2c.entropy_coef : 0.0);
  }
  if (c.hidden_size() == 0) {
    for (int64_t h : NetworkConfig().hidden) c.add_hidden(h);
  }
  if (!c.has_scale_rewards()) c.set_scale_rewards(false);
  if (!c.has_max_kl()) c.set_max_kl(algorithms.trpo.max_kl);
  if (!c.has_checkpoint_every()) c.set_checkpoint_every(10);
  if (!c.has_keep_checkpoints()) c.set_keep_checkpoints(3);
  if (!c.has_sync()) c.set_sync(true);
  if (!c.has_max_policy_lag()) c.set_max_policy_lag(c.sync() ? 0 : 4);
  if (!c.has_segment_length()) {
    c.set_segment_length(std::min<int64_t>(128, c.horizon()));
  }

  absl::StatusOr<Statistic> statistic = ParseStatistic(c.estimator());
  if (!statistic.ok())
    return Invalid("estimator:", statistic.status().message());
  if (c.steps() < 1) return Invalid("steps", "must be >= 1");
  if (c.envs() < 1 || c.envs() > 4096) {
    return Invalid("envs", "must be in [1, 4096]");
  }
  if (c.horizon() < 1) return Invalid("horizon", "must be >= 1");
  if (a2c && c.horizon() % algorithms.a2c.steps_per_minibatch != 0) {
    return Invalid("horizon", absl::StrCat("must be a multiple of a2c's ",
                                           algorithms.a2c.steps_per_minibatch,
                                           "-step minibatches"));
  }
  if (c.epochs() < 1) return Invalid("epochs", "must be >= 1");
  if (!(c.learning_rate() > 0)) return Invalid("learning_rate", "must be > 0");
  if (!(c.entropy_coef() >= 0)) return Invalid("entropy_coef", "must be >= 0");
  if (!(c.max_kl() > 0)) return Invalid("max_kl", "must be > 0");
  for (int64_t h : c.hidden()) {
    if (h < 1) return Invalid("hidden", "sizes must be >= 1");
  }
  if (c.checkpoint_every() < 1)
    return Invalid("checkpoint_every", "must be >= 1");
  if (c.sync() && c.max_policy_lag() != 0) {
    return Invalid("max_policy_lag", "must be 0 with --sync");
  }
  if (c.max_policy_lag() < 0) return Invalid("max_policy_lag", "must be >= 0");
  if (c.segment_length() < 1 || c.segment_length() > c.horizon()) {
    return Invalid("segment_length", "must be in [1, --horizon]");
  }
  if (c.sync() && c.horizon() % c.segment_length() != 0) {
    return Invalid("segment_length",
                   "must divide --horizon in a --sync run (each actor sends "
                   "exactly one horizon per policy version)");
  }
  if (c.keep_checkpoints() < 1)
    return Invalid("keep_checkpoints", "must be >= 1");
  // The estimator's own rules (gamma, lambda, rho, ensemble).
  const LocalTrainingConfig local = ToLocalTrainingConfig(c);
  if (absl::Status status = local.learner.advantage.Validate(); !status.ok()) {
    return absl::InvalidArgumentError(
        absl::StrCat("estimator settings: ", status.message()));
  }
  if (absl::Status status = local.learner.algorithm.Validate(); !status.ok()) {
    return absl::InvalidArgumentError(
        absl::StrCat(c.algo(), " settings: ", status.message()));
  }
  return c;
}

absl::StatusOr<pb::RunConfig> ParseRunConfigJson(const std::string& json) {
  pb::RunConfig config;
  const auto status =
      google::protobuf::util::JsonStringToMessage(json, &config);
  if (!status.ok()) {
    return absl::InvalidArgumentError(
        absl::StrCat("run config: ", status.message().as_string()));
  }
  return config;
}

absl::StatusOr<pb::RunConfig> ReadRunConfigFile(const std::string& path) {
  std::ifstream file(path);
  if (!file) {
    return absl::NotFoundError(absl::StrCat("cannot read config file ", path));
  }
  std::stringstream text;
  text << file.rdbuf();
  absl::StatusOr<pb::RunConfig> config = ParseRunConfigJson(text.str());
  if (!config.ok()) {
    return absl::InvalidArgumentError(
        absl::StrCat(path, ": ", config.status().message()));
  }
  return config;
}

std::string RunConfigToJson(const pb::RunConfig& config) {
  google::protobuf::util::JsonPrintOptions options;
  options.add_whitespace = true;
  options.preserve_proto_field_names = true;
  std::string json;
  (void)google::protobuf::util::MessageToJsonString(config, &json, options);
  return json;
}

LocalTrainingConfig ToLocalTrainingConfig(const pb::RunConfig& c) {
  LocalTrainingConfig local;
  local.env = c.env();
  local.num_envs = c.envs();
  local.total_env_steps = c.steps();
  local.seed = c.seed();
  LearnerConfig& learner = local.learner;
  learner.horizon = c.horizon();
  learner.max_policy_lag = c.max_policy_lag();
  local.segment_length = c.segment_length();
  learner.scale_rewards = c.scale_rewards();
  learner.network.hidden.assign(c.hidden().begin(), c.hidden().end());
  AdvantageConfig& advantage = learner.advantage;
  if (absl::StatusOr<Statistic> statistic = ParseStatistic(c.estimator());
      statistic.ok()) {
    advantage.statistic = *statistic;
  }
  advantage.rho = c.rho();
  advantage.gamma = c.gamma();
  advantage.lambda = c.gae_lambda();
  advantage.ensemble.assign(c.ensemble().begin(), c.ensemble().end());
  AlgorithmConfig& algorithm = learner.algorithm;
  algorithm.name = c.algo();
  algorithm.ppo.minibatches = c.minibatches();
  algorithm.ppo.epochs = c.epochs();
  algorithm.ppo.learning_rate = c.learning_rate();
  algorithm.ppo.entropy_coef = c.entropy_coef();
  algorithm.a2c.minibatches = c.minibatches();
  algorithm.a2c.learning_rate = c.learning_rate();
  algorithm.a2c.entropy_coef = c.entropy_coef();
  algorithm.trpo.value_learning_rate = c.learning_rate();
  algorithm.trpo.entropy_coef = c.entropy_coef();
  algorithm.trpo.max_kl = c.max_kl();
  return local;
}

}  // namespace vantage
