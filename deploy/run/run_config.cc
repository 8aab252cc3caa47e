#include "deploy/run/run_config.h"

#include <algorithm>
#include <numeric>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_replace.h"
#include "actor/evaluation_config.h"
#include "actor/run_settings.h"
#include "deploy/run/distributed_config.h"
#include "deploy/run/run_plan.h"
#include "learner/algorithms/algorithm_config.h"
#include "learner/exploration/ex2_config.h"
#include "learner/learner_settings.h"
#include "learner/run/recording_config.h"
#include "proto/settings_table.h"

namespace vantage {
namespace {

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

// A recurrent core's chunks: whole segments by default (or the
// algorithm's minibatch steps if those are fewer), dividing the segments
// (whose start states the actors send), and the segments dividing the
// horizon (so that every rollout starts with a segment's state).
absl::Status ResolveSequences(const AlgorithmRunDefaults& run_defaults,
                              pb::TrainingSettings& t) {
  // Without a core, --core_size and --seq_len were refused already.
  if (!NamesACore(t)) return absl::OkStatus();
  if (t.horizon() % t.segment_length() != 0) {
    return FlagError("segment_length",
                     absl::StrCat("must divide --horizon (", t.horizon(),
                                  ") with a recurrent --core: each rollout "
                                  "starts with a segment's state"));
  }
  const int64_t slice = run_defaults.horizon_multiple;
  if (t.seq_len() == 0) {
    t.set_seq_len(std::gcd(t.segment_length(), slice > 1 ? slice : 0));
  }
  if (t.segment_length() % t.seq_len() != 0) {
    return FlagError("seq_len",
                     absl::StrCat("must divide --segment_length (",
                                  t.segment_length(), "), got ", t.seq_len()));
  }
  if (slice > 1 && slice % t.seq_len() != 0) {
    return FlagError("seq_len",
                     absl::StrCat("must divide the algorithm's minibatch "
                                  "steps (",
                                  slice, "), got ", t.seq_len()));
  }
  return absl::OkStatus();
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
    return FlagError("envs", "must be in [1, 4096]");
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
    return FlagError("segment_length", "must be in [1, --horizon]");
  }
  return ResolveSequences(run_defaults, t);
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
    return FlagError("segment_length",
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
    return FlagError("mode:", absl::StrCat("unknown mode '", c.mode(),
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
  if (absl::Status status = ResolveEvaluationSettings(c); !status.ok()) {
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

}  // namespace vantage
