#include "deploy/run/run_config.h"

#include <google/protobuf/util/json_util.h>
#include <google/protobuf/util/message_differencer.h>

#include <algorithm>
#include <fstream>
#include <sstream>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_replace.h"
#include "absl/strings/str_split.h"
#include "common/advantage/advantage_config.h"
#include "common/env/frame_stack.h"
#include "deploy/run/distributed_config.h"
#include "deploy/run/run_plan.h"
#include "learner/algorithms/a2c/a2c_config.h"
#include "learner/algorithms/algorithm_config.h"
#include "learner/exploration/ex2_config.h"
#include "learner/learner_settings.h"
#include "learner/run/recording_config.h"
#include "proto/flat_run_config.pb.h"

namespace vantage {
namespace {

absl::Status Invalid(absl::string_view flag, absl::string_view rule) {
  return absl::InvalidArgumentError(absl::StrCat("--", flag, " ", rule));
}

// An algorithm's or exploration method's rule names its field
// ("ppo.epochs must be >= 1"); the message adds the field's flag
// (--ppo_epochs).
absl::Status AlgorithmSettingError(absl::string_view rule) {
  const absl::string_view field = rule.substr(0, rule.find(' '));
  if (field.find('.') == absl::string_view::npos) {
    return absl::InvalidArgumentError(rule);
  }
  return absl::InvalidArgumentError(absl::StrCat(
      rule, " (--", absl::StrReplaceAll(field, {{".", "_"}}), ")"));
}

// An actor sends segments of at most this many steps by default: the
// largest divisor of the horizon up to it, so that a segment never spans
// two rollouts (which local and --sync runs need).
constexpr int64_t kSegmentSteps = 128;

// The run's own defaults: what a run that names no task trains and for how
// long (its other defaults are the components').
constexpr char kDefaultEnv[] = "InvertedPendulum";
constexpr int64_t kDefaultSteps = 150000;

int64_t DefaultSegmentLength(int64_t horizon) {
  for (int64_t length = std::min(kSegmentSteps, horizon); length > 1;
       --length) {
    if (horizon % length == 0) return length;
  }
  return 1;
}

// The algorithm of an older run's flat config.json, with the flat fields
// whose meaning depended on it.
absl::Status AlgorithmFromFlat(const pb::FlatRunConfig& flat,
                               pb::RunConfig& c) {
  const std::string algo = flat.has_algo() ? flat.algo() : "ppo";
  if (absl::Status status = SelectAlgorithm(algo, c); !status.ok()) {
    return Invalid("algo:", status.message());
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

// The training section: the learner's settings, then the actor's (whose
// segments default to a divisor of the horizon); --envs only checked here,
// since the run's layout (distributed or local) decides it.
absl::Status ResolveTraining(const AlgorithmConfig& algorithm,
                             const AlgorithmRunDefaults& run_defaults,
                             pb::TrainingSettings& t) {
  LearnerConfig learner;
  learner.total_env_steps = kDefaultSteps;
  if (absl::Status status =
          ResolveLearnerTraining(learner, run_defaults, algorithm.name, t);
      !status.ok()) {
    return status;
  }
  if (t.has_envs() && (t.envs() < 1 || t.envs() > 4096)) {
    return Invalid("envs", "must be in [1, 4096]");
  }
  // Whether the algorithm can share a torso is the learner's rule, checked
  // with the others once the config is whole.
  ActorConfig actor;
  actor.env = kDefaultEnv;
  actor.segment_length = DefaultSegmentLength(t.horizon());
  if (absl::Status status = ResolveActorSettings(actor, t); !status.ok()) {
    return status;
  }
  if (t.segment_length() < 1 || t.segment_length() > t.horizon()) {
    return Invalid("segment_length", "must be in [1, --horizon]");
  }
  return absl::OkStatus();
}

// A local run: one strictly on-policy process.
absl::Status ResolveLocal(pb::RunConfig& c) {
  if (c.has_distributed()) {
    return absl::InvalidArgumentError(
        "--mode=local runs one strictly on-policy process: drop the "
        "distributed settings (--actors, --envs_per_actor, --sync, "
        "--max_policy_lag, --learners, --learner_threads)");
  }
  pb::TrainingSettings& t = *c.mutable_training();
  if (!t.has_envs()) t.set_envs(ActorConfig().num_envs);
  if (t.horizon() % t.segment_length() != 0) {
    return Invalid("segment_length",
                   "must divide --horizon in a local run (its actor sends "
                   "each rollout as whole segments)");
  }
  return absl::OkStatus();
}

}  // namespace

absl::StatusOr<pb::RunConfig> ResolveRunConfig(const pb::RunConfig& given) {
  pb::RunConfig c = given;
  // The main job is the distributed one; --mode=local keeps one process.
  if (!c.has_mode()) c.set_mode("distributed");
  if (c.mode() != "local" && c.mode() != "distributed") {
    return Invalid("mode:", absl::StrCat("unknown mode '", c.mode(),
                                         "'; available: local, distributed"));
  }
  AlgorithmConfig algorithm = AlgorithmConfigOf(c);
  if (absl::Status status = algorithm.Validate(); !status.ok()) {
    return AlgorithmSettingError(status.message());
  }
  SetAlgorithmSettings(algorithm, c);
  const AlgorithmRunDefaults run_defaults = RunDefaultsOf(algorithm);
  // An exploration section naming no method means none.
  const ExplorationConfig exploration = ExplorationConfigOf(c);
  if (exploration.ex2.has_value()) {
    if (absl::Status status = exploration.ex2->Validate(); !status.ok()) {
      return AlgorithmSettingError(status.message());
    }
  }
  SetExplorationSettings(exploration, c);
  if (absl::Status status =
          ResolveTraining(algorithm, run_defaults, *c.mutable_training());
      !status.ok()) {
    return status;
  }
  if (absl::Status status =
          ResolveAdvantageSettings(run_defaults, *c.mutable_advantage());
      !status.ok()) {
    return status;
  }
  if (absl::Status status =
          c.mode() == "distributed"
              ? ResolveDistributedSettings(*c.mutable_training(),
                                           *c.mutable_distributed())
              : ResolveLocal(c);
      !status.ok()) {
    return status;
  }
  if (absl::Status status = ResolveRecordingSettings(*c.mutable_recording());
      !status.ok()) {
    return status;
  }
  // The rules of the learner's own config (a shared torso's algorithm),
  // the estimator's (gamma, lambda, rho, ensemble) among them.
  absl::StatusOr<RunPlan> plan = PlanRun(c);
  if (!plan.ok()) return plan.status();
  if (absl::Status status = plan->learner.advantage.Validate(); !status.ok()) {
    return absl::InvalidArgumentError(
        absl::StrCat("estimator settings: ", status.message()));
  }
  if (absl::Status status = plan->learner.ValidateSettings(); !status.ok()) {
    return status;
  }
  return c;
}

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
