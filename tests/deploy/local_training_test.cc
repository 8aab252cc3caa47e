#include "deploy/run/local_training.h"

#include <ATen/Parallel.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "common/util/cpu_model.h"
#include "deploy/run/trained_policy.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "learner/checkpoint/checkpoint.h"
#include "learner/run/progress_columns.h"
#include "learner/run/run_directory.h"
#include "tests/fakes/local_plan.h"
#include "tests/fakes/run_files.h"

namespace vantage {
namespace {

constexpr int64_t kHorizon = 128;
constexpr int kEnvs = 2;
constexpr int kUpdates = 6;

// A fresh, empty directory under the test's temporary directory.
std::string FreshDirectory(const std::string& name) {
  const std::string path = std::string(::testing::TempDir()) + "/" + name;
  std::filesystem::remove_all(path);
  return path;
}

// `name`: an algorithm, or "ex2", optionally with a recurrent core
// ("ppo_gru": PPO with a GRU of 16 units), evaluations ("ppo_eval": of
// 3 episodes every 2 updates), masked actions ("ppo_masked": on
// LitButtons instead of Hopper) or a Dict observation ("ppo_dict": on
// LitButtons:dict=true), or TRPO's linear baseline ("trpo_linear").
RunPlan SmallRun(const std::string& name, uint64_t seed,
                 const std::string& run_dir) {
  const std::vector<std::string> parts = absl::StrSplit(name, '_');
  const std::string& algorithm = parts[0];
  pb::RunConfig run;
  pb::TrainingSettings& training = *run.mutable_training();
  training.set_env("Hopper");
  if (parts.size() > 1 && parts[1] == "eval") {
    run.mutable_evaluation()->set_eval_every(2);
    run.mutable_evaluation()->set_eval_episodes(3);
  } else if (parts.size() > 1 && parts[1] == "masked") {
    training.set_env("LitButtons");
  } else if (parts.size() > 1 && parts[1] == "dict") {
    training.set_env("LitButtons:dict=true");
  } else if (parts.size() > 1 && parts[1] == "linear") {
    run.mutable_trpo()->set_linear_baseline(true);
  } else if (parts.size() > 1) {
    training.set_core(parts[1]);
    training.set_core_size(16);
  }
  training.set_envs(kEnvs);
  // A2C's rollouts are 5n steps (n = 4 here).
  training.set_steps(kUpdates * kEnvs * (algorithm == "a2c" ? 20 : kHorizon));
  training.set_seed(seed);
  // Reward scaling carries state across updates (per-stream returns), so
  // the resume tests cover it.
  training.set_scale_rewards(true);
  if (algorithm == "ppo") {
    training.set_horizon(kHorizon);
    run.mutable_ppo()->set_minibatches(8);
    run.mutable_ppo()->set_epochs(2);
  } else if (algorithm == "a2c") {
    run.mutable_a2c()->set_n(4);
  } else {
    training.set_horizon(kHorizon);
    run.mutable_trpo();
  }
  // "ex2": TRPO with an EX2 bonus small enough to fit on update 3, whose
  // pool (1000 states) wraps around after four batches.
  if (algorithm == "ex2") {
    pb::Ex2Settings& ex2 = *run.mutable_exploration()->mutable_ex2();
    ex2.add_hidden(16);
    ex2.set_feature_dim(8);
    ex2.set_replay_min(300);
    ex2.set_replay_size(1000);
    ex2.set_first_train_iterations(30);
    ex2.set_train_iterations(10);
    ex2.set_batch_size(32);
    ex2.set_bonus_coeff(0.1);
  }
  run.mutable_advantage()->set_estimator("max");
  run.mutable_advantage()->set_rho(0.5);
  run.mutable_recording()->set_checkpoint_every(2);
  RunPlan plan = LocalPlan(run);
  plan.recording.run_dir = run_dir;
  return plan;
}

// Runs to the end, or stops after update `stop_after` like a killed run.
void Train(const RunPlan& config, int stop_after = kUpdates) {
  const absl::Status status =
      RunLocalTraining(config, [&](const ProgressRow& row) {
        return row.stats.policy_version < stop_after;
      });
  ASSERT_TRUE(status.ok()) << status;
}

TEST(LocalTrainingTest, SameSeedSameProgressCsv) {
  at::set_num_threads(1);
  const std::string a = FreshDirectory("same_seed_a");
  const std::string b = FreshDirectory("same_seed_b");
  const std::string c = FreshDirectory("other_seed");
  Train(SmallRun("ppo", 4, a));
  Train(SmallRun("ppo", 4, b));
  Train(SmallRun("ppo", 5, c));
  const std::vector<std::string> first = DeterministicProgress(a);
  ASSERT_EQ(first.size(), 1u + kUpdates);
  EXPECT_EQ(first[0],
            "env_steps,updates,policy_version,episodes,mean_return,"
            "policy_loss,value_loss,entropy,approx_kl,clip_fraction,"
            "explained_variance,biased_fraction,mean_abs_bias,"
            "rejected_segments,rolled_back_updates,batch_actors,"
            "batch_env_slots,exploration_loss,"
            "exploration_accuracy,exploration_bonus,exploration_bonus_std,"
            "eval_version,eval_return,"
            "eval_return_std,eval_return_min,eval_return_max,eval_length");
  EXPECT_EQ(first, DeterministicProgress(b));
  EXPECT_NE(first, DeterministicProgress(c));
  // One row per update, steps counted exactly.
  EXPECT_THAT(first[1], ::testing::StartsWith("256,1,1,"));
  EXPECT_THAT(first[kUpdates], ::testing::StartsWith("1536,6,6,"));
}

// A progress.csv written by a vantage with fewer columns is carried over
// column by column when a resumed run cuts it back: rows keep their values
// under the same names and the new columns stay empty.
TEST(LocalTrainingTest, ResumingMigratesAnOlderProgressFile) {
  const std::string dir = FreshDirectory("old_columns");
  absl::StatusOr<RunDirectory> run = RunDirectory::Create(dir, "{}");
  ASSERT_TRUE(run.ok()) << run.status();
  {
    std::ofstream old(dir + "/progress.csv");
    old << "env_steps,updates,mean_return,sps\n"
        << "256,1,12.5,900\n"
        << "512,2,13.5,950\n";
  }
  ASSERT_TRUE(run->TruncateProgress(1).ok());
  std::ifstream file(dir + "/progress.csv");
  std::string header, row, rest;
  std::getline(file, header);
  std::getline(file, row);
  EXPECT_EQ(header, ProgressHeader());
  EXPECT_FALSE(std::getline(file, rest));  // update 2 is cut
  const std::vector<std::string> names = absl::StrSplit(header, ',');
  const std::vector<std::string> values = absl::StrSplit(row, ',');
  ASSERT_EQ(values.size(), names.size());
  for (size_t i = 0; i < names.size(); ++i) {
    const std::string expected = names[i] == "env_steps"     ? "256"
                                 : names[i] == "updates"     ? "1"
                                 : names[i] == "mean_return" ? "12.5"
                                 : names[i] == "sps"         ? "900"
                                                             : "";
    EXPECT_EQ(values[i], expected) << names[i];
  }
}

// machine.json names every CPU model that ran a part of the run: a run
// resumed on another machine lists both.
TEST(LocalTrainingTest, ARunRecordsTheMachinesThatRanIt) {
  const std::string dir = FreshDirectory("machines");
  Train(SmallRun("ppo", 1, dir), /*stop_after=*/2);
  const auto read = [&] {
    std::ifstream file(dir + "/machine.json");
    std::stringstream text;
    text << file.rdbuf();
    return text.str();
  };
  const std::string here = CpuModel();
  EXPECT_EQ(read(), "{\"cpu_models\": [\n  \"" + here + "\"\n]}\n");
  std::ofstream(dir + "/machine.json")
      << "{\"cpu_models\": [\n  \"Elsewhere 9000\"\n]}\n";
  RunPlan resume = SmallRun("ppo", 1, dir);
  resume.recording.resume = true;
  Train(resume, /*stop_after=*/3);
  EXPECT_EQ(read(), "{\"cpu_models\": [\n  \"Elsewhere 9000\",\n  \"" + here +
                        "\"\n]}\n");
}

TEST(LocalTrainingTest, RefusesADirectoryThatHoldsARun) {
  const std::string dir = FreshDirectory("taken");
  Train(SmallRun("ppo", 1, dir), /*stop_after=*/1);
  const absl::Status status = RunLocalTraining(
      SmallRun("ppo", 1, dir), [](const ProgressRow&) { return true; });
  EXPECT_EQ(status.code(), absl::StatusCode::kAlreadyExists);
  EXPECT_THAT(std::string(status.message()), ::testing::HasSubstr("--resume"));
}

class ResumeTest : public ::testing::TestWithParam<std::string> {};

// A run killed after update 5 (its last checkpoint is from update 4, and
// progress.csv already has row 5) and resumed gives the uninterrupted
// run's progress.csv, row for row.
TEST_P(ResumeTest, ResumedRunEqualsUninterruptedRun) {
  at::set_num_threads(1);
  const std::string whole = FreshDirectory("whole_" + GetParam());
  const std::string broken = FreshDirectory("broken_" + GetParam());
  Train(SmallRun(GetParam(), 7, whole));
  Train(SmallRun(GetParam(), 7, broken), /*stop_after=*/5);
  EXPECT_EQ(DeterministicProgress(broken).size(), 1u + 5);
  RunPlan resume = SmallRun(GetParam(), 7, broken);
  resume.recording.resume = true;
  Train(resume);
  EXPECT_EQ(DeterministicProgress(broken), DeterministicProgress(whole));
  // Checkpoints at 2, 4 and 6 (the end); the newest 3 are kept.
  EXPECT_EQ(ListCheckpoints(broken + "/checkpoints").size(), 3u);
}

INSTANTIATE_TEST_SUITE_P(Algorithms, ResumeTest,
                         ::testing::Values("ppo", "a2c", "trpo", "ex2",
                                           "ppo_gru", "a2c_lstm", "ppo_eval",
                                           "ppo_masked", "a2c_masked",
                                           "trpo_masked", "ppo_dict",
                                           "trpo_linear"));

// Every second version is evaluated before its row, which holds the
// evaluation; checkpoints/best.pt is the version whose evaluation was best
// (best.json says which) and loads as a trained policy.
TEST(LocalTrainingTest, EvaluationsFillTheirRowsAndKeepTheBestCheckpoint) {
  at::set_num_threads(1);
  const std::string dir = FreshDirectory("evaluated");
  Train(SmallRun("ppo_eval", 3, dir));
  const std::vector<std::string> rows = DeterministicProgress(dir);
  ASSERT_EQ(rows.size(), 1u + kUpdates);
  int64_t best_version = -1;
  double best_return = -1e300;
  for (int version = 1; version <= kUpdates; ++version) {
    const auto field = [&](const std::string& column) {
      return ProgressField(rows, version, column);
    };
    if (version % 2 != 0) {
      EXPECT_EQ(field("eval_version"), "") << version;
      EXPECT_EQ(field("eval_return"), "") << version;
      continue;
    }
    EXPECT_EQ(field("eval_version"), std::to_string(version));
    double mean = 0, low = 0, high = 0;
    ASSERT_TRUE(absl::SimpleAtod(field("eval_return"), &mean));
    ASSERT_TRUE(absl::SimpleAtod(field("eval_return_min"), &low));
    ASSERT_TRUE(absl::SimpleAtod(field("eval_return_max"), &high));
    EXPECT_LE(low, mean);
    EXPECT_LE(mean, high);
    if (mean > best_return) {
      best_return = mean;
      best_version = version;
    }
  }
  std::ifstream json(dir + "/checkpoints/best.json");
  std::stringstream text;
  text << json.rdbuf();
  EXPECT_THAT(text.str(), ::testing::HasSubstr(absl::StrCat(
                              "\"version\": ", best_version, ",")));
  absl::StatusOr<TrainedPolicy> best =
      LoadTrainedPolicy(dir + "/checkpoints/best.pt");
  ASSERT_TRUE(best.ok()) << best.status();
  EXPECT_EQ(best->version, best_version);
  for (const auto& entry :
       std::filesystem::directory_iterator(dir + "/checkpoints")) {
    EXPECT_THAT(entry.path().filename().string(),
                ::testing::Not(::testing::StartsWith("evaluating-")));
  }
}

// The rows without the three exploration columns.
std::vector<std::string> WithoutExploration(
    const std::vector<std::string>& rows) {
  const std::vector<std::string> names = absl::StrSplit(ProgressHeader(), ',');
  std::vector<std::string> kept;
  for (const std::string& row : rows) {
    const std::vector<std::string> fields = absl::StrSplit(row, ',');
    std::vector<std::string> others;
    for (size_t i = 0; i < fields.size(); ++i) {
      if (!absl::StartsWith(names.at(i), "exploration_")) {
        others.push_back(fields[i]);
      }
    }
    kept.push_back(absl::StrJoin(others, ","));
  }
  return kept;
}

// The bonus enters only through the rewards, and the model draws from its
// own generator: at bonus_coeff 0 a run trains exactly as without it, and
// at 0.1 it trains otherwise.
TEST(LocalTrainingTest, Ex2ChangesTrainingOnlyThroughTheRewards) {
  at::set_num_threads(1);
  const std::string plain = FreshDirectory("plain_trpo");
  const std::string silent = FreshDirectory("silent_ex2");
  const std::string shaped = FreshDirectory("shaped_ex2");
  Train(SmallRun("trpo", 7, plain));
  RunPlan config = SmallRun("ex2", 7, silent);
  config.learner.exploration.ex2->bonus_coeff = 0.0;
  Train(config);
  Train(SmallRun("ex2", 7, shaped));
  const std::vector<std::string> silent_rows = DeterministicProgress(silent);
  EXPECT_EQ(WithoutExploration(silent_rows),
            WithoutExploration(DeterministicProgress(plain)));
  EXPECT_NE(WithoutExploration(DeterministicProgress(shaped)),
            WithoutExploration(DeterministicProgress(plain)));
  // Updates 1-2: no model yet (bonus 0, no fit); 3: the first fit.
  const auto field = [&](int row, const std::string& name) {
    return ProgressField(silent_rows, row, name);
  };
  EXPECT_EQ(field(1, "exploration_bonus"), "0");
  EXPECT_EQ(field(1, "exploration_bonus_std"), "0");
  EXPECT_EQ(field(1, "exploration_loss"), "");
  EXPECT_NE(field(2, "exploration_bonus"), "0");
  EXPECT_GT(std::stod(field(2, "exploration_bonus_std")), 0.0);
  EXPECT_NE(field(3, "exploration_loss"), "");
  EXPECT_GT(std::stod(field(3, "exploration_accuracy")), 0.0);
}

// A damaged newest checkpoint is reported and skipped: the run continues
// from the one before it and still ends where the uninterrupted run did.
TEST(LocalTrainingTest, ResumeSkipsADamagedNewestCheckpoint) {
  at::set_num_threads(1);
  const std::string whole = FreshDirectory("whole_damaged");
  const std::string broken = FreshDirectory("broken_damaged");
  Train(SmallRun("ppo", 8, whole));
  Train(SmallRun("ppo", 8, broken), /*stop_after=*/5);
  const std::string newest = CheckpointPath(broken + "/checkpoints", 4);
  ASSERT_TRUE(std::filesystem::exists(newest));
  std::ofstream(newest, std::ios::trunc) << "not a checkpoint";
  RunPlan resume = SmallRun("ppo", 8, broken);
  resume.recording.resume = true;
  Train(resume);
  EXPECT_EQ(DeterministicProgress(broken), DeterministicProgress(whole));
}

TEST(LocalTrainingTest, ResumeWithoutCheckpointsIsAnError) {
  const std::string dir = FreshDirectory("no_checkpoints");
  RunPlan config = SmallRun("ppo", 1, dir);
  config.recording.resume = true;
  EXPECT_EQ(
      RunLocalTraining(config, [](const ProgressRow&) { return true; }).code(),
      absl::StatusCode::kNotFound);
}

}  // namespace
}  // namespace vantage
