#include "deploy/run/run_config_file.h"

#include <google/protobuf/util/json_util.h>
#include <google/protobuf/util/message_differencer.h>

#include <fstream>
#include <sstream>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "learner/algorithms/a2c/a2c_config.h"
#include "learner/algorithms/algorithm_config.h"
#include "proto/flat_run_config.pb.h"

namespace vantage {
namespace {

// The algorithm of an older run's flat config.json, with the flat fields
// whose meaning depended on it.
absl::Status AlgorithmFromFlat(const pb::FlatRunConfig& flat,
                               pb::RunConfig& c) {
  const std::string algo = flat.has_algo() ? flat.algo() : "ppo";
  if (absl::Status status = SelectAlgorithm(algo, c); !status.ok()) {
    return absl::InvalidArgumentError(
        absl::StrCat("--algo: ", status.message()));
  }
  if (algo == "a2c") {
    pb::A2cSettings& s = *c.mutable_a2c();
    // A2C updated over horizon / 5 minibatches whatever minibatches said.
    const int64_t steps = A2cConfig().steps_per_minibatch;
    if (flat.has_horizon() && flat.horizon() % steps == 0) {
      s.set_n(static_cast<int32_t>(flat.horizon() / steps));
    } else if (flat.has_minibatches()) {
      s.set_n(flat.minibatches());
    }
    if (flat.has_learning_rate()) s.set_learning_rate(flat.learning_rate());
    if (flat.has_entropy_coef()) s.set_entropy_coef(flat.entropy_coef());
  } else if (algo == "trpo") {
    pb::TrpoSettings& s = *c.mutable_trpo();
    if (flat.has_max_kl()) s.set_max_kl(flat.max_kl());
    if (flat.has_learning_rate()) {
      s.set_value_learning_rate(flat.learning_rate());
    }
    if (flat.has_entropy_coef()) s.set_entropy_coef(flat.entropy_coef());
  } else if (algo == "ppo") {
    pb::PpoSettings& s = *c.mutable_ppo();
    if (flat.has_epochs()) s.set_epochs(flat.epochs());
    if (flat.has_minibatches()) s.set_minibatches(flat.minibatches());
    if (flat.has_learning_rate()) s.set_learning_rate(flat.learning_rate());
    if (flat.has_entropy_coef()) s.set_entropy_coef(flat.entropy_coef());
  }
  return absl::OkStatus();
}

// The fields of an older run's flat config.json in their sections; the
// flat fields whose meaning depended on the algorithm go to its section.
absl::StatusOr<pb::RunConfig> FromFlat(const pb::FlatRunConfig& flat) {
  pb::RunConfig c;
  if (flat.has_mode()) c.set_mode(flat.mode());
  pb::TrainingSettings& t = *c.mutable_training();
  if (flat.has_env()) t.set_env(flat.env());
  if (flat.has_seed()) t.set_seed(flat.seed());
  if (flat.has_steps()) t.set_steps(flat.steps());
  if (flat.has_envs()) t.set_envs(flat.envs());
  if (flat.has_horizon()) t.set_horizon(flat.horizon());
  t.mutable_hidden()->CopyFrom(flat.hidden());
  if (flat.has_scale_rewards()) t.set_scale_rewards(flat.scale_rewards());
  if (flat.has_segment_length()) t.set_segment_length(flat.segment_length());
  pb::AdvantageSettings& a = *c.mutable_advantage();
  if (flat.has_estimator()) a.set_estimator(flat.estimator());
  if (flat.has_rho()) a.set_rho(flat.rho());
  a.mutable_ensemble()->CopyFrom(flat.ensemble());
  if (flat.has_gamma()) a.set_gamma(flat.gamma());
  if (flat.has_gae_lambda()) a.set_gae_lambda(flat.gae_lambda());
  if (absl::Status status = AlgorithmFromFlat(flat, c); !status.ok()) {
    return status;
  }
  pb::RecordingSettings& r = *c.mutable_recording();
  if (flat.has_checkpoint_every()) {
    r.set_checkpoint_every(flat.checkpoint_every());
  }
  if (flat.has_keep_checkpoints()) {
    r.set_keep_checkpoints(flat.keep_checkpoints());
  }
  // A local run's flat config held (unused) synchronous settings.
  if (c.mode() != "local") {
    pb::DistributedSettings& d = *c.mutable_distributed();
    if (flat.has_actors()) d.set_actors(flat.actors());
    if (flat.has_envs_per_actor()) d.set_envs_per_actor(flat.envs_per_actor());
    if (flat.has_sync()) d.set_sync(flat.sync());
    if (flat.has_max_policy_lag()) d.set_max_policy_lag(flat.max_policy_lag());
  }
  return c;
}

}  // namespace

absl::StatusOr<pb::RunConfig> ParseRunConfigJson(const std::string& json) {
  pb::RunConfig config;
  const auto status =
      google::protobuf::util::JsonStringToMessage(json, &config);
  if (status.ok()) return config;
  pb::FlatRunConfig flat;
  if (google::protobuf::util::JsonStringToMessage(json, &flat).ok()) {
    return FromFlat(flat);
  }
  return absl::InvalidArgumentError(
      absl::StrCat("run config: ", status.message().as_string()));
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

std::string RunConfigDifference(const pb::RunConfig& held,
                                const pb::RunConfig& wanted) {
  std::string report;
  google::protobuf::util::MessageDifferencer differencer;
  differencer.ReportDifferencesToString(&report);
  if (differencer.Compare(held, wanted)) return "";
  const std::vector<std::string> lines =
      absl::StrSplit(report, '\n', absl::SkipEmpty());
  return lines.empty() ? "the configs differ" : lines.front();
}

}  // namespace vantage
