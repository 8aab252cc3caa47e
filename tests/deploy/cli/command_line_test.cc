// The `vantage` command line as a user meets it: every command holds to
// its own flags, has help, and reads --flagfile exactly like the command
// line; help's defaults are what a run's config.json records and does.

#include <cstdlib>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "absl/algorithm/container.h"
#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"
#include "deploy/cli/run_flags.h"
#include "deploy/run/run_config.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "learner/algorithms/algorithm.h"
#include "tests/deploy/cli/run_vantage.h"
#include "tests/fakes/run_files.h"

namespace vantage {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;
using ::testing::StartsWith;

int Lines(const std::string& text) {
  return static_cast<int>(std::count(text.begin(), text.end(), '\n'));
}

// The command names `vantage help` lists.
std::vector<std::string> CommandNames() {
  const Outcome help = RunVantage("help");
  EXPECT_EQ(help.exit_code, 0) << help.err;
  std::vector<std::string> names;
  bool listing = false;
  for (absl::string_view line : absl::StrSplit(help.out, '\n')) {
    if (line == "commands:") {
      listing = true;
    } else if (listing && absl::ConsumePrefix(&line, "  ")) {
      const std::string name(line.substr(0, line.find(' ')));
      if (name != "help") names.push_back(name);
    }
  }
  return names;
}

// "--name=value" lines of `vantage help CMD`.
std::map<std::string, std::string> HelpDefaults(const std::string& command) {
  const Outcome help = RunVantage("help " + command);
  EXPECT_EQ(help.exit_code, 0) << help.err;
  std::map<std::string, std::string> defaults;
  for (absl::string_view line : absl::StrSplit(help.out, '\n')) {
    if (!absl::ConsumePrefix(&line, "  --")) continue;
    const size_t equals = line.find('=');
    defaults[std::string(line.substr(0, equals))] =
        std::string(line.substr(equals + 1));
  }
  return defaults;
}

TEST(CommandLineTest, EveryCommandHasHelp) {
  const std::vector<std::string> names = CommandNames();
  for (const char* expected :
       {"actor", "advantages", "envs", "learner", "rollout", "train"}) {
    EXPECT_THAT(names, testing::Contains(expected));
  }
  for (const std::string& name : names) {
    const Outcome help = RunVantage("help " + name);
    ASSERT_EQ(help.exit_code, 0) << name << ": " << help.err;
    EXPECT_THAT(help.out, StartsWith("usage: vantage " + name)) << name;
    EXPECT_THAT(help.out, HasSubstr("\nexample:\n  vantage " + name)) << name;
    // `vantage CMD --help` is the same text, and none is absl's or
    // Google Benchmark's.
    EXPECT_EQ(RunVantage(name + " --help").out, help.out) << name;
    EXPECT_THAT(help.out, Not(HasSubstr("benchmark_filter"))) << name;
    EXPECT_THAT(help.out, Not(HasSubstr("Flags from"))) << name;
  }
  const Outcome unknown = RunVantage("help nothing");
  EXPECT_EQ(unknown.exit_code, 2);
  EXPECT_THAT(unknown.err, HasSubstr("name one command of: actor"));
  EXPECT_EQ(RunVantage("--help").exit_code, 0);
  EXPECT_EQ(RunVantage("").exit_code, 2);
}

// The run flags come from the run-config proto: each setting is a flag of
// `vantage train`, with its help line, and a run flag's value reaches the
// run's config however it is written.
TEST(CommandLineTest, EveryRunSettingIsAFlagOfTrain) {
  const std::map<std::string, std::string> defaults = HelpDefaults("train");
  for (const std::string& name : RunSettingNames()) {
    EXPECT_EQ(defaults.count(name), 1u) << "--" << name;
  }
  const Outcome help = RunVantage("help train");
  EXPECT_THAT(help.out, HasSubstr("  --ppo_clip=0.2\n      ppo: the ratio's "
                                  "clip range\n"));
  const std::string run = FreshDirectory("declared");
  const Outcome outcome = RunVantage(
      "train --mode=distributed --actors 1 --envs_per_actor=2 --nosync "
      "--max_policy_lag 2 --steps=512 --horizon=128 --hidden 8,8 "
      "--ppo_normalize_advantages=false --env=InvertedPendulum --run_dir=" +
      run);
  ASSERT_EQ(outcome.exit_code, 0) << outcome.err;
  const std::string config = ReadFile(run + "/config.json");
  EXPECT_THAT(config, HasSubstr("\"sync\": false"));
  EXPECT_THAT(config, HasSubstr("\"max_policy_lag\": \"2\""));
  EXPECT_THAT(config, HasSubstr("\"normalize_advantages\": false"));
}

TEST(CommandLineTest, AFlagOfAnotherCommandIsAOneLineUsageError) {
  const std::pair<std::string, std::string> cases[] = {
      {"envs --rho=5", "--rho is not a flag of `vantage envs`"},
      {"rollout --algo=xyz --env=Hopper",
       "--algo is not a flag of `vantage rollout`"},
      {"learner --mode=local", "--mode is not a flag of `vantage learner`"},
      {"advantages --example --env=Hopper",
       "--env is not a flag of `vantage advantages`"},
      {"actor --learner=127.0.0.1:1 --steps=5",
       "--steps is not a flag of `vantage actor`"},
      {"train --listen=0.0.0.0:1", "--listen is not a flag of `vantage train`"},
      {"train --nosync --noexample",
       "--example is not a flag of `vantage train`"},
      {"envs --frobnicate", "unknown flag --frobnicate"},
      {"train --benchmark_filter=all", "unknown flag --benchmark_filter"},
      {"rollout --env=Hopper --episodes=many", "--episodes=many"},
      {"rollout --env Hopper --episodes", "--episodes needs a value"},
  };
  for (const auto& [args, message] : cases) {
    const Outcome outcome = RunVantage(args);
    EXPECT_EQ(outcome.exit_code, 2) << args << ": " << outcome.err;
    EXPECT_THAT(outcome.err, HasSubstr(message)) << args;
    EXPECT_THAT(outcome.err, StartsWith("vantage ")) << args;
    EXPECT_EQ(Lines(outcome.err), 1) << args << ": " << outcome.err;
  }
  // A value in the next argument belongs to its flag.
  const Outcome separate = RunVantage("rollout --env Hopper --episodes 1");
  EXPECT_EQ(separate.exit_code, 0) << separate.err;
}

TEST(CommandLineTest, AFlagfileIsTheCommandLine) {
  const std::string flags =
      "--mode=local --steps=512 --horizon=128 --envs=2 --seed=5 "
      "--estimator=max --rho=0.7 --ensemble=1,8,32 --ppo_epochs=3 "
      "--ppo_minibatches=4";
  const std::string direct = FreshDirectory("direct");
  ASSERT_EQ(RunVantage("train " + flags + " --run_dir=" + direct).exit_code, 0);
  std::string lines;
  for (absl::string_view flag : absl::StrSplit(flags, ' ')) {
    absl::StrAppend(&lines, flag, "\n");
  }
  const std::string from_file = FreshDirectory("from_file");
  const Outcome outcome =
      RunVantage("train --flagfile=" + WriteTemp("train.flags", lines) +
                 " --run_dir=" + from_file);
  ASSERT_EQ(outcome.exit_code, 0) << outcome.err;
  EXPECT_EQ(ReadFile(from_file + "/config.json"),
            ReadFile(direct + "/config.json"));
  EXPECT_THAT(ReadFile(direct + "/config.json"), HasSubstr("\"rho\": 0.7"));
  EXPECT_THAT(ReadFile(direct + "/config.json"), HasSubstr("\"epochs\": 3"));
  EXPECT_EQ(DeterministicProgress(from_file), DeterministicProgress(direct));
  // A flagfile is held to the command's flags too.
  const Outcome foreign =
      RunVantage("envs --flagfile=" + WriteTemp("envs.flags", "--rho=0.5\n"));
  EXPECT_EQ(foreign.exit_code, 2);
  EXPECT_THAT(foreign.err, HasSubstr("--rho is not a flag of `vantage envs`"));
}

// A mistake inside a flagfile is a usage error (exit 2) naming the flag or
// the line, as the same mistake on the command line is.
TEST(CommandLineTest, MistakesInAFlagfileAreUsageErrors) {
  const struct {
    std::string lines;
    std::string message;
  } cases[] = {
      {"--steps=64\n--no_such_flag=1\n", "unknown flag --no_such_flag"},
      {"# a comment\n\n--steps=many\n", "--steps 'many' is not an integer"},
      {"--steps=64\nsteps=64\n",
       "line 2: 'steps=64' is not a flag (one --name=value per line)"},
      {"--flagfile=/no/such/file.flags\n",
       "--flagfile=/no/such/file.flags: cannot read it"},
  };
  int index = 0;
  for (const auto& [lines, message] : cases) {
    const std::string file =
        WriteTemp(absl::StrCat("mistake", index++, ".flags"), lines);
    const Outcome outcome = RunVantage("train --flagfile " + file);
    EXPECT_EQ(outcome.exit_code, 2) << lines << outcome.err;
    EXPECT_THAT(outcome.err, HasSubstr(message)) << lines;
    EXPECT_THAT(outcome.err, HasSubstr("vantage train: ")) << lines;
  }
  const Outcome missing = RunVantage("train --flagfile=/no/such.flags");
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_THAT(missing.err, HasSubstr("--flagfile=/no/such.flags: cannot "
                                     "read it"));
}

// For each algorithm: what `vantage help train` says an absent flag means
// is what a fresh run's config.json holds, and the run does it (each
// update consumes envs x horizon steps).
TEST(CommandLineTest, HelpDefaultsAreTheRunsConfigAndBehaviour) {
  const std::map<std::string, std::string> help = HelpDefaults("train");
  for (const std::string variant : {"ppo", "a2c", "trpo", "trpo+ex2"}) {
    // "+ex2": with --exploration=ex2, whose settings only it holds.
    const bool ex2 = absl::EndsWith(variant, "+ex2");
    const std::string algo = variant.substr(0, variant.find('+'));
    const std::string run =
        FreshDirectory("defaults_" + algo + (ex2 ? "_ex2" : ""));
    const Outcome outcome =
        RunVantage("train --mode=local --steps=1 --algo=" + algo +
                   (ex2 ? " --exploration=ex2" : "") + " --run_dir=" + run);
    ASSERT_EQ(outcome.exit_code, 0) << outcome.err;
    absl::StatusOr<pb::RunConfig> config =
        ReadRunConfigFile(run + "/config.json");
    ASSERT_TRUE(config.ok()) << config.status();
    for (const std::string& name : RunFlagNames(/*with_mode=*/true)) {
      if (name == "mode" || name == "algo" || name == "steps" ||
          name == "config" || name == "run_dir" || name == "resume" ||
          name == "resume_if_exists" || name == "exploration") {
        continue;
      }
      // A feed-forward run's config holds no core settings (its help says
      // what a core takes).
      if (name == "core" || name == "core_size" || name == "seq_len") {
        EXPECT_EQ(RunConfigFieldText(*config, name), "") << variant << name;
        continue;
      }
      // Nor does a run without evaluations hold theirs (its help says
      // "none" and what an evaluation plays).
      if (name == "eval_every" || name == "eval_episodes") {
        EXPECT_EQ(RunConfigFieldText(*config, name), "") << variant << name;
        continue;
      }
      if (absl::StartsWith(name, "ex2_") && !ex2) {
        EXPECT_EQ(RunConfigFieldText(*config, name), "") << variant << name;
        continue;
      }
      // Another algorithm's settings are not in this run's config.
      const size_t prefix = name.find('_');
      if (prefix != std::string::npos &&
          absl::c_linear_search(AlgorithmNames(), name.substr(0, prefix))) {
        if (name.substr(0, prefix) != algo) {
          EXPECT_EQ(RunConfigFieldText(*config, name), "") << algo << name;
          continue;
        }
      }
      ASSERT_EQ(help.count(name), 1u) << name;
      std::string expected = help.at(name);
      // "ppo: 2048; a2c: 20; trpo: 1024 (--mode=local: 1)": this run's part.
      if (const size_t local = expected.find(" (--mode=local: ");
          local != std::string::npos) {
        expected = expected.substr(local + 16);
        expected.pop_back();
      }
      for (absl::string_view part : absl::StrSplit(expected, "; ")) {
        if (absl::ConsumePrefix(&part, algo + ": "))
          expected = std::string(part);
      }
      if (expected == "\"\"" || expected == "unused") expected = "";
      EXPECT_EQ(RunConfigFieldText(*config, name), expected)
          << algo << " --" << name;
    }
    // One update of envs x horizon steps: the first progress row's steps.
    const std::vector<std::string> rows = DeterministicProgress(run);
    ASSERT_GE(rows.size(), 2u);
    int64_t steps = 0;
    ASSERT_TRUE(absl::SimpleAtoi(rows[1].substr(0, rows[1].find(',')), &steps))
        << rows[1];
    EXPECT_EQ(steps, config->training().envs() * config->training().horizon())
        << algo;
  }
}

// docs/cli.md is the binary's own help (docs/make_cli_docs.sh writes it).
TEST(CommandLineTest, TheReferenceIsTheHelp) {
  const std::string reference = ReadFile(VANTAGE_SOURCE_DIR "/docs/cli.md");
  ASSERT_FALSE(reference.empty());
  for (const std::string& name : CommandNames()) {
    EXPECT_THAT(reference, HasSubstr(RunVantage("help " + name).out))
        << "docs/cli.md is out of date for `vantage " << name
        << "`: run docs/make_cli_docs.sh";
  }
}

}  // namespace
}  // namespace vantage
