#include "deploy/run/run_config.h"

#include <limits>

#include "deploy/run/distributed_config.h"
#include "deploy/run/run_plan.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "learner/algorithms/a2c/a2c_config.h"
#include "learner/algorithms/ppo/ppo_config.h"
#include "learner/algorithms/trpo/trpo_config.h"

namespace vantage {
namespace {

using ::testing::HasSubstr;

absl::StatusOr<pb::RunConfig> Resolve(const std::string& json) {
  absl::StatusOr<pb::RunConfig> parsed = ParseRunConfigJson(json);
  EXPECT_TRUE(parsed.ok()) << parsed.status();
  if (!parsed.ok()) return parsed.status();
  return ResolveRunConfig(*parsed);
}

TEST(RunConfigTest, DistributedBatchIsActorsTimesEnvsPerActor) {
  absl::StatusOr<pb::RunConfig> config =
      Resolve(R"({"distributed": {"actors": 3, "envs_per_actor": 4}})");
  ASSERT_TRUE(config.ok()) << config.status();
  EXPECT_EQ(config->training().envs(), 12);
}

// actors x envs_per_actor used to overflow an int32 (undefined behaviour,
// found by tests/fuzz/run_config_fuzzer's UBSan build).
TEST(RunConfigTest, TooManyEnvsPerActorAreRefused) {
  for (const std::string& json :
       {std::string(R"({"distributed": {"envs_per_actor": 2147483647}})"),
        std::string(
            R"({"distributed": {"actors": 256, "envs_per_actor": 4097}})")}) {
    const absl::Status status = Resolve(json).status();
    EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument) << json;
    EXPECT_THAT(std::string(status.message()),
                HasSubstr("--envs_per_actor must be in [1, 4096]"))
        << json;
  }
  const absl::Status status =
      Resolve(R"({"distributed": {"actors": 256, "envs_per_actor": 4096}})")
          .status();
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(status.message()),
              HasSubstr("--envs_per_actor makes --actors x --envs_per_actor = "
                        "1048576 streams, more than 4096"));
}

// Each default comes from the component that owns it.
TEST(RunConfigTest, DefaultsAreTheComponentsOwn) {
  absl::StatusOr<pb::RunConfig> config = Resolve("{}");
  ASSERT_TRUE(config.ok()) << config.status();
  EXPECT_EQ(config->mode(), "distributed");
  EXPECT_EQ(config->training().env(), "InvertedPendulum");
  EXPECT_EQ(config->training().steps(), 150000);
  EXPECT_EQ(config->training().seed(), ActorConfig().seed);
  EXPECT_EQ(config->training().scale_rewards(), LearnerConfig().scale_rewards);
  EXPECT_EQ(config->advantage().rho(), AdvantageConfig().rho);
  EXPECT_EQ(config->advantage().estimator(), "maxabs");
  EXPECT_EQ(config->ppo().minibatches(), PpoConfig().minibatches);
  EXPECT_EQ(config->recording().checkpoint_every(),
            RecordingConfig().checkpoint_every);
  EXPECT_EQ(config->training().frame_stack(), 1);
  EXPECT_TRUE(config->training().normalize_observations());
  // Only the chosen algorithm's section is there.
  EXPECT_EQ(config->algorithm_case(), pb::RunConfig::kPpo);
  absl::StatusOr<pb::RunConfig> a2c = Resolve(R"({"a2c": {"n": 3}})");
  ASSERT_TRUE(a2c.ok()) << a2c.status();
  EXPECT_EQ(a2c->training().horizon(), 15);
  EXPECT_EQ(a2c->advantage().gae_lambda(), 1.0);
  EXPECT_EQ(a2c->a2c().entropy_coef(), A2cConfig().entropy_coef);
  absl::StatusOr<pb::RunConfig> local_run = Resolve(R"({"mode": "local"})");
  ASSERT_TRUE(local_run.ok()) << local_run.status();
  EXPECT_FALSE(local_run->has_distributed());
  EXPECT_EQ(local_run->training().envs(), ActorConfig().num_envs);
}

// The recording and distributed sections are read through their
// components' tables (learner/run/recording_config.cc,
// deploy/run/distributed_config.cc): defaults from DistributedConfig and
// RecordingConfig, each range's message naming the flag.
TEST(RunConfigTest, SectionTablesGiveDefaultsAndNameTheFlag) {
  absl::StatusOr<pb::RunConfig> config = Resolve("{}");
  ASSERT_TRUE(config.ok()) << config.status();
  const DistributedConfig distributed;
  EXPECT_EQ(config->distributed().actors(), distributed.actors);
  EXPECT_EQ(config->distributed().sync(), distributed.sync);
  EXPECT_EQ(config->distributed().max_policy_lag(), 0);
  EXPECT_EQ(config->distributed().learners(), distributed.learners);
  EXPECT_EQ(config->distributed().learner_threads(),
            distributed.learner_threads);
  EXPECT_EQ(config->recording().keep_checkpoints(),
            RecordingConfig().keep_checkpoints);
  absl::StatusOr<pb::RunConfig> async =
      Resolve(R"({"distributed": {"sync": false}})");
  ASSERT_TRUE(async.ok()) << async.status();
  EXPECT_EQ(async->distributed().max_policy_lag(), 4);
  const std::pair<const char*, const char*> refusals[] = {
      {R"({"recording": {"checkpoint_every": 0}})",
       "--checkpoint_every must be >= 1"},
      {R"({"recording": {"keep_checkpoints": -2}})",
       "--keep_checkpoints must be >= 1"},
      {R"({"distributed": {"actors": 257}})", "--actors must be in [1, 256]"},
      {R"({"distributed": {"learners": 65}})", "--learners must be in [1, 64]"},
      {R"({"distributed": {"learner_threads": -1}})",
       "--learner_threads must be in [0, 256] (0: automatic)"},
      {R"({"distributed": {"sync": false, "max_policy_lag": -1}})",
       "--max_policy_lag must be >= 0"},
      {R"({"distributed": {"actors": 3, "learners": 2}})",
       "--learners must divide --actors (3): every learner serves as many "
       "actors"},
  };
  for (const auto& [json, message] : refusals) {
    EXPECT_EQ(Resolve(json).status().message(), message) << json;
  }
}

TEST(RunConfigTest, FrameStacksAreOneToSixteen) {
  for (const char* json : {R"({"training": {"frame_stack": 0}})",
                           R"({"training": {"frame_stack": 17}})"}) {
    EXPECT_EQ(Resolve(json).status().message(),
              "--frame_stack must be in [1, 16]")
        << json;
  }
  absl::StatusOr<pb::RunConfig> config =
      Resolve(R"({"training": {"env": "MinAtarBreakout", "frame_stack": 4}})");
  ASSERT_TRUE(config.ok()) << config.status();
  EXPECT_EQ(EnvOptionsOf(*config).frame_stack, 4);
  absl::StatusOr<RunPlan> plan = PlanRun(*config);
  ASSERT_TRUE(plan.ok()) << plan.status();
  EXPECT_EQ(plan->actor.env_options.frame_stack, 4);
  // A config from before frame stacking existed stacks nothing.
  EXPECT_EQ(EnvOptionsOf(pb::RunConfig()).frame_stack, 1);
}

TEST(RunConfigTest, ASharedTorsoNeedsOneOptimiserOverBothNetworks) {
  absl::StatusOr<pb::RunConfig> separate = Resolve("{}");
  ASSERT_TRUE(separate.ok()) << separate.status();
  EXPECT_FALSE(separate->training().shared_torso());
  absl::StatusOr<pb::RunConfig> shared = Resolve(
      R"({"training": {"env": "MinAtarBreakout", "shared_torso": true},
          "a2c": {}})");
  ASSERT_TRUE(shared.ok()) << shared.status();
  absl::StatusOr<RunPlan> plan = PlanRun(*shared);
  ASSERT_TRUE(plan.ok()) << plan.status();
  EXPECT_TRUE(plan->learner.network.shared_torso);
  EXPECT_TRUE(plan->actor.network.shared_torso);
  EXPECT_EQ(
      Resolve(R"({"training": {"shared_torso": true}, "trpo": {}})")
          .status()
          .message(),
      "--shared_torso needs ppo or a2c, which step both networks with one "
      "optimiser; trpo fits its value network alone");
}

// TRPO's linear baseline is a setting of TRPO's (the learner refuses it
// for images: learner_core_test).
TEST(RunConfigTest, TheLinearBaselineIsTrposSetting) {
  absl::StatusOr<pb::RunConfig> linear = Resolve(
      R"({"training": {"env": "Hopper"}, "trpo": {"linear_baseline": true}})");
  ASSERT_TRUE(linear.ok()) << linear.status();
  absl::StatusOr<RunPlan> plan = PlanRun(*linear);
  ASSERT_TRUE(plan.ok()) << plan.status();
  EXPECT_TRUE(plan->learner.linear_critic());
  absl::StatusOr<pb::RunConfig> ppo = Resolve(R"({"training": {}})");
  ASSERT_TRUE(ppo.ok()) << ppo.status();
  EXPECT_FALSE(PlanRun(*ppo)->learner.linear_critic());
}

// A recurrent core: its settings appear in the config only with a core;
// its chunks default to whole segments (a2c: its minibatches' steps); each
// rule names its flag.
// Evaluation settings are in a run's config only when it evaluates, so
// every config from before them resolves as it did.
TEST(RunConfigTest, EvaluationsResolveOnlyWhenTheRunEvaluates) {
  absl::StatusOr<pb::RunConfig> plain = Resolve(R"({"training": {}})");
  ASSERT_TRUE(plain.ok()) << plain.status();
  EXPECT_FALSE(plain->has_evaluation());
  EXPECT_FALSE(PlanRun(*plain)->evaluation.enabled());
  absl::StatusOr<pb::RunConfig> off =
      Resolve(R"({"evaluation": {"eval_every": 0}})");
  ASSERT_TRUE(off.ok()) << off.status();
  EXPECT_FALSE(off->has_evaluation());
  absl::StatusOr<pb::RunConfig> on =
      Resolve(R"({"evaluation": {"eval_every": 5}})");
  ASSERT_TRUE(on.ok()) << on.status();
  EXPECT_EQ(on->evaluation().eval_every(), 5);
  EXPECT_EQ(on->evaluation().eval_episodes(), 10);
  absl::StatusOr<RunPlan> plan = PlanRun(*on);
  ASSERT_TRUE(plan.ok()) << plan.status();
  EXPECT_EQ(plan->evaluation.every, 5);
  EXPECT_EQ(plan->evaluation.episodes, 10);
  const auto error = [](const std::string& json) {
    return std::string(Resolve(json).status().message());
  };
  EXPECT_THAT(error(R"({"evaluation": {"eval_every": 5, "eval_episodes": 0}})"),
              HasSubstr("--eval_episodes must be in [1, 100000]"));
  EXPECT_THAT(error(R"({"evaluation": {"eval_every": -2}})"),
              HasSubstr("--eval_every must be >= 0"));
  EXPECT_THAT(error(R"({"evaluation": {"eval_episodes": 3}})"),
              HasSubstr("--eval_episodes needs --eval_every"));
}

TEST(RunConfigTest, ARecurrentCoreResolvesItsChunksAndNamesEveryRule) {
  absl::StatusOr<pb::RunConfig> plain = Resolve(R"({"training": {}})");
  ASSERT_TRUE(plain.ok()) << plain.status();
  EXPECT_FALSE(plain->training().has_core_size());
  EXPECT_FALSE(plain->training().has_seq_len());
  absl::StatusOr<pb::RunConfig> gru =
      Resolve(R"({"training": {"env": "CueRecall", "core": "gru"}})");
  ASSERT_TRUE(gru.ok()) << gru.status();
  EXPECT_EQ(gru->training().core_size(), 64);
  EXPECT_EQ(gru->training().seq_len(), 128);
  absl::StatusOr<RunPlan> plan = PlanRun(*gru);
  ASSERT_TRUE(plan.ok()) << plan.status();
  EXPECT_EQ(plan->learner.network.core, Core::kGru);
  EXPECT_EQ(plan->learner.network.seq_len, 128);
  EXPECT_EQ(plan->actor.network.core_state_size(), 64);
  absl::StatusOr<pb::RunConfig> a2c =
      Resolve(R"({"training": {"core": "lstm"}, "a2c": {}})");
  ASSERT_TRUE(a2c.ok()) << a2c.status();
  EXPECT_EQ(a2c->training().seq_len(), 5);
  const auto error = [](const std::string& json) {
    return std::string(Resolve(json).status().message());
  };
  EXPECT_THAT(error(R"({"training": {"core": "rnn"}})"),
              HasSubstr("'rnn' is not one of none, gru, lstm"));
  EXPECT_THAT(error(R"({"training": {"seq_len": 16}})"),
              HasSubstr("--seq_len needs a recurrent --core (gru or lstm)"));
  EXPECT_THAT(error(R"({"training": {"core_size": 16}})"),
              HasSubstr("--core_size needs a recurrent --core"));
  EXPECT_THAT(error(R"({"training": {"core": "gru", "core_size": 0}})"),
              HasSubstr("core_size"));
  EXPECT_THAT(
      error(R"({"training": {"core": "gru", "seq_len": 48}})"),
      HasSubstr("--seq_len must divide --segment_length (128), got 48"));
  EXPECT_THAT(error(R"({"training": {"core": "gru", "horizon": 300,
                             "segment_length": 128}})"),
              HasSubstr("--segment_length must divide --horizon (300) with a "
                        "recurrent --core"));
  EXPECT_THAT(
      error(R"({"training": {"core": "gru", "seq_len": 2},
                         "a2c": {}})"),
      HasSubstr(
          "--seq_len must divide the algorithm's minibatch steps (5), got 2"));
  EXPECT_THAT(error(R"({"training": {"core": "gru"}, "trpo": {}})"),
              HasSubstr("--core=gru needs ppo or a2c: the policy and the value "
                        "network share the core"));
}

// One resolved config, one plan: what the actor and the learner both need
// is read once and agrees.
TEST(RunConfigTest, ThePlanGivesActorAndLearnerTheSameRun) {
  absl::StatusOr<pb::RunConfig> config = Resolve(
      R"({"mode": "local", "training": {"env": "Hopper", "envs": 3,
          "seed": 9, "horizon": 96, "segment_length": 32, "hidden": [8],
          "steps": 5000}, "trpo": {"max_kl": 0.02},
          "recording": {"keep_checkpoints": 5}})");
  ASSERT_TRUE(config.ok()) << config.status();
  absl::StatusOr<RunPlan> plan = PlanRun(*config);
  ASSERT_TRUE(plan.ok()) << plan.status();
  EXPECT_EQ(plan->actor.env, "Hopper");
  EXPECT_EQ(plan->actor.num_envs, 3);
  EXPECT_EQ(plan->learner.rollouts_per_batch, 3);
  EXPECT_EQ(plan->actor.seed, 9u);
  EXPECT_EQ(plan->learner.seed, 9u);
  EXPECT_EQ(plan->actor.segment_length, 32);
  EXPECT_EQ(plan->learner.max_segment_steps, 32);
  EXPECT_EQ(plan->learner.horizon, 96);
  EXPECT_EQ(plan->learner.total_env_steps, 5000);
  EXPECT_EQ(plan->actor.network.hidden, std::vector<int64_t>{8});
  EXPECT_EQ(plan->learner.network.hidden, std::vector<int64_t>{8});
  EXPECT_EQ(plan->actor.observation_clip, plan->learner.observation_clip);
  EXPECT_EQ(plan->learner.algorithm.name, "trpo");
  EXPECT_EQ(plan->learner.algorithm.Get<TrpoConfig>().max_kl, 0.02);
  EXPECT_EQ(plan->learner.advantage.lambda, 0.98);  // TRPO's own default
  EXPECT_EQ(plan->recording.keep_checkpoints, 5);
  EXPECT_EQ(plan->recording.config_json, RunConfigToJson(*config));
  EXPECT_TRUE(plan->recording.run_dir.empty());
  EXPECT_TRUE(plan->learner.ValidateSettings().ok());
}

// Unnormalised observations reach the networks unclipped, in the actors
// and in the learner alike (remote actors read the run config themselves).
TEST(RunConfigTest, UnnormalisedObservationsAreNotClipped) {
  absl::StatusOr<pb::RunConfig> config = Resolve(
      R"({"mode": "local", "training": {"normalize_observations": false}})");
  ASSERT_TRUE(config.ok()) << config.status();
  EXPECT_FALSE(config->training().normalize_observations());
  absl::StatusOr<RunPlan> plan = PlanRun(*config);
  ASSERT_TRUE(plan.ok()) << plan.status();
  EXPECT_FALSE(plan->learner.normalize_observations);
  EXPECT_EQ(plan->actor.observation_clip,
            std::numeric_limits<double>::infinity());
  EXPECT_EQ(plan->learner.observation_clip, plan->actor.observation_clip);
  EXPECT_EQ(ActorConfigOf(*config)->observation_clip,
            plan->actor.observation_clip);
  absl::StatusOr<RunPlan> normalised =
      PlanRun(*Resolve(R"({"mode": "local"})"));
  ASSERT_TRUE(normalised.ok()) << normalised.status();
  EXPECT_TRUE(normalised->learner.normalize_observations);
  EXPECT_EQ(normalised->actor.observation_clip, ActorConfig().observation_clip);
}

// Time limits bootstrap unless the run says otherwise, and the learner is
// told so.
TEST(RunConfigTest, ATimeLimitEndsTheReturnWhereTheRunSaysSo) {
  absl::StatusOr<pb::RunConfig> config = Resolve(
      R"({"mode": "local", "training": {"bootstrap_time_limits": false}})");
  ASSERT_TRUE(config.ok()) << config.status();
  EXPECT_FALSE(config->training().bootstrap_time_limits());
  absl::StatusOr<RunPlan> plan = PlanRun(*config);
  ASSERT_TRUE(plan.ok()) << plan.status();
  EXPECT_FALSE(plan->learner.bootstrap_time_limits);
  absl::StatusOr<pb::RunConfig> defaults = Resolve(R"({"mode": "local"})");
  ASSERT_TRUE(defaults.ok()) << defaults.status();
  EXPECT_TRUE(defaults->training().bootstrap_time_limits());
  EXPECT_TRUE(PlanRun(*defaults)->learner.bootstrap_time_limits);
}

TEST(RunConfigTest, AResolvedConfigSurvivesItsJsonAndResolvingAgain) {
  for (
      const std::string& json :
      {std::string("{}"), std::string(R"({"mode": "local", "trpo": {}})"),
       std::string(
           R"({"mode": "local", "training": {"normalize_observations": false, "core": "gru"}})"),
       std::string(R"({"a2c": {"n": 2}, "distributed": {"sync": false}})")}) {
    absl::StatusOr<pb::RunConfig> config = Resolve(json);
    ASSERT_TRUE(config.ok()) << config.status();
    absl::StatusOr<pb::RunConfig> again =
        ParseRunConfigJson(RunConfigToJson(*config));
    ASSERT_TRUE(again.ok()) << again.status();
    EXPECT_EQ(again->SerializeAsString(), config->SerializeAsString()) << json;
    // Resolving is idempotent: experiment directories resolve the records
    // they hold again before comparing them with their cells.
    absl::StatusOr<pb::RunConfig> twice = ResolveRunConfig(*config);
    ASSERT_TRUE(twice.ok()) << twice.status();
    EXPECT_EQ(RunConfigDifference(*twice, *config), "") << json;
  }
}

// A run directory's config.json from before the sections: the fields
// whose meaning depended on the algorithm land in its section.
TEST(RunConfigTest, FlatConfigsOfOlderRunsAreConverted) {
  absl::StatusOr<pb::RunConfig> a2c = Resolve(
      R"({"mode": "local", "env": "Hopper", "algo": "a2c", "envs": 4,
          "horizon": 20, "minibatches": 4, "learning_rate": 0.001,
          "entropy_coef": 0.02, "epochs": 10, "max_kl": 0.01, "sync": true,
          "max_policy_lag": "0", "estimator": "min", "rho": 0.3,
          "ensemble": ["1", "5", "20"], "checkpoint_every": 5})");
  ASSERT_TRUE(a2c.ok()) << a2c.status();
  EXPECT_EQ(a2c->a2c().n(), 4);
  EXPECT_EQ(a2c->a2c().learning_rate(), 0.001);
  EXPECT_EQ(a2c->a2c().entropy_coef(), 0.02);
  EXPECT_EQ(a2c->training().env(), "Hopper");
  EXPECT_EQ(a2c->training().horizon(), 20);
  EXPECT_EQ(a2c->advantage().estimator(), "min");
  EXPECT_EQ(a2c->advantage().ensemble_size(), 3);
  EXPECT_EQ(a2c->recording().checkpoint_every(), 5);
  EXPECT_FALSE(a2c->has_distributed());

  absl::StatusOr<pb::RunConfig> trpo =
      Resolve(R"({"algo": "trpo", "learning_rate": 0.002, "max_kl": 0.02,
                  "actors": 2, "envs_per_actor": 3, "sync": false})");
  ASSERT_TRUE(trpo.ok()) << trpo.status();
  EXPECT_EQ(trpo->trpo().value_learning_rate(), 0.002);
  EXPECT_EQ(trpo->trpo().max_kl(), 0.02);
  EXPECT_EQ(trpo->training().envs(), 6);
  EXPECT_FALSE(trpo->distributed().sync());
  EXPECT_EQ(trpo->distributed().max_policy_lag(), 4);

  absl::StatusOr<pb::RunConfig> ppo =
      Resolve(R"({"minibatches": 8, "epochs": 3, "learning_rate": 0.01})");
  ASSERT_TRUE(ppo.ok()) << ppo.status();
  EXPECT_EQ(ppo->ppo().minibatches(), 8);
  EXPECT_EQ(ppo->ppo().epochs(), 3);
  EXPECT_EQ(ppo->ppo().learning_rate(), 0.01);

  const absl::StatusOr<pb::RunConfig> unknown =
      ParseRunConfigJson(R"({"algo": "sac"})");
  EXPECT_THAT(std::string(unknown.status().message()),
              HasSubstr("unknown algorithm 'sac'"));
  // Neither format: the message is the current format's.
  const absl::StatusOr<pb::RunConfig> neither =
      ParseRunConfigJson(R"({"trainin": {}})");
  EXPECT_THAT(std::string(neither.status().message()), HasSubstr("trainin"));
}

}  // namespace
}  // namespace vantage
