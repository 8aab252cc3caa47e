// The transport benchmarks run end to end and print their RESULT lines
// (their figures are for docs/benchmarks.md, not for assertions here).

#include <cstdlib>
#include <map>
#include <string>
#include <vector>

#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/deploy/cli/run_vantage.h"

namespace vantage {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

// key=value pairs of the line starting with `prefix`.
std::map<std::string, std::string> ResultFields(const std::string& out,
                                                const std::string& prefix) {
  std::map<std::string, std::string> fields;
  for (absl::string_view line : absl::StrSplit(out, '\n')) {
    if (!absl::ConsumePrefix(&line, prefix)) continue;
    for (absl::string_view pair : absl::StrSplit(line, ' ')) {
      std::pair<std::string, std::string> kv = absl::StrSplit(pair, '=');
      fields[kv.first] = kv.second;
    }
  }
  return fields;
}

double Number(const std::map<std::string, std::string>& fields,
              const std::string& key) {
  double value = -1;
  auto found = fields.find(key);
  if (found == fields.end() || !absl::SimpleAtod(found->second, &value)) {
    return -1;
  }
  return value;
}

TEST(BenchCommandsTest, IngestStreamsIntoALearnerAndCountsActorsFed) {
  const Outcome outcome =
      RunVantage("bench ingest --bench_clients=2 --bench_seconds=0.5");
  ASSERT_EQ(outcome.exit_code, 0) << outcome.err;
  const auto fields = ResultFields(outcome.out, "RESULT ingest ");
  EXPECT_EQ(fields.at("clients"), "2");
  const double ingested = Number(fields, "steps_per_s");
  const double actor = Number(fields, "actor_steps_per_s");
  EXPECT_GT(ingested, 0);
  EXPECT_GT(actor, 0);
  EXPECT_NEAR(Number(fields, "actors_fed"), ingested / actor,
              0.06 + 0.001 * ingested / actor);
}

TEST(BenchCommandsTest, ActorStreamsIntoALearnerAgainstRawPhysics) {
  const Outcome outcome =
      RunVantage("bench actor --env=Hopper --envs=2 --bench_seconds=0.5");
  ASSERT_EQ(outcome.exit_code, 0) << outcome.err;
  const auto fields = ResultFields(outcome.out, "RESULT actor ");
  EXPECT_EQ(fields.at("env"), "Hopper");
  EXPECT_EQ(fields.at("envs"), "2");
  const double raw = Number(fields, "raw_steps_per_s");
  const double actor = Number(fields, "actor_steps_per_s");
  EXPECT_GT(raw, 0);
  EXPECT_GT(actor, 0);
  EXPECT_NEAR(Number(fields, "ratio"), actor / raw, 0.002);
}

TEST(BenchCommandsTest, BadFlagsAreClearErrors) {
  const Outcome outcome = RunVantage("bench ingest --bench_clients=0");
  EXPECT_EQ(outcome.exit_code, 2);
  EXPECT_THAT(outcome.err, HasSubstr("--bench_clients must be >= 1"));
  EXPECT_THAT(RunVantage("bench actor --envs=0").err,
              HasSubstr("--envs must be >= 1"));
  EXPECT_THAT(RunVantage("bench actor --env=Nope").err,
              HasSubstr("unknown environment 'Nope'"));
  const Outcome unknown = RunVantage("bench nothing");
  EXPECT_EQ(unknown.exit_code, 2);
  EXPECT_THAT(unknown.err,
              HasSubstr("name one benchmark of: actor, advantages"));
}

// Google Benchmark colours its output whenever TERM is set; its escape
// codes must not reach a pipe, where they would precede the RESULT line.
TEST(BenchCommandsTest, ResultLinesCarryNoColourCodes) {
  setenv("TERM", "xterm-256color", 1);
  const Outcome outcome =
      RunVantage("bench actor --env=Hopper --envs=1 --bench_seconds=0.2");
  ASSERT_EQ(outcome.exit_code, 0) << outcome.err;
  bool found = false;
  for (absl::string_view line : absl::StrSplit(outcome.out, '\n')) {
    found = found || absl::StartsWith(line, "RESULT actor ");
  }
  EXPECT_TRUE(found) << outcome.out;
  EXPECT_THAT(outcome.out, Not(HasSubstr("\033[")));
}

// limit_sps as documented: cores / (1 / raw + passes / update), with the
// samples/s of vantage's own update in the field `update_field`.
void ExpectTheLimitOf(const std::map<std::string, std::string>& fields,
                      const std::string& update_field, int passes) {
  const double raw = Number(fields, "raw_steps_per_s");
  const double update = Number(fields, update_field);
  const double cores = Number(fields, "cores");
  ASSERT_GT(raw, 0);
  ASSERT_GT(update, 0);
  ASSERT_GE(cores, 1);
  const double limit = Number(fields, "limit_sps");
  EXPECT_NEAR(limit, cores / (1 / raw + passes / update), 0.01 * limit + 1);
}

// The distributed main job against the machine's limit, with two learners:
// the limit is computed as documented from the figures it prints.
TEST(BenchCommandsTest, TrainTimesTheMainJobAgainstTheMachinesLimit) {
  const Outcome outcome = RunVantage(
      "bench train --env=InvertedPendulum --steps=10240 --horizon=512 "
      "--learners=2");
  ASSERT_EQ(outcome.exit_code, 0) << outcome.err;
  // One RESULT line per configuration: sync, then async with lag 1.
  std::vector<std::map<std::string, std::string>> results;
  for (absl::string_view line : absl::StrSplit(outcome.out, '\n')) {
    if (absl::StartsWith(line, "RESULT train ")) {
      results.push_back(ResultFields(std::string(line), "RESULT train "));
    }
  }
  ASSERT_EQ(results.size(), 2u) << outcome.out;
  EXPECT_EQ(results[0].at("sync"), "1");
  EXPECT_EQ(results[0].at("max_policy_lag"), "0");
  EXPECT_EQ(results[1].at("sync"), "0");
  EXPECT_EQ(results[1].at("max_policy_lag"), "1");
  for (const auto& fields : results) {
    EXPECT_EQ(fields.at("env"), "InvertedPendulum");
    EXPECT_EQ(fields.at("algo"), "ppo");
    EXPECT_EQ(fields.at("learners"), "2");
    EXPECT_EQ(fields.at("actors"), "2");
    ExpectTheLimitOf(fields, "ppo_update_samples_per_s", 10);
    // The bare LibTorch loop's limit beside it, for comparison.
    const double bare = Number(fields, "bare_samples_per_s");
    ASSERT_GT(bare, 0);
    const double bare_limit = Number(fields, "bare_limit_sps");
    EXPECT_NEAR(bare_limit,
                Number(fields, "cores") /
                    (1 / Number(fields, "raw_steps_per_s") + 10 / bare),
                0.01 * bare_limit + 1);
    const double limit = Number(fields, "limit_sps");
    EXPECT_GT(Number(fields, "sps"), 0);
    EXPECT_NEAR(Number(fields, "ratio"), Number(fields, "sps") / limit, 0.002);
    // The time splits the learners and actors printed: shares of their
    // wall time that add up to all of it.
    double learner = 0.0, actor = 0.0;
    for (const char* phase : {"advantages", "optimisation", "bookkeeping",
                              "publish", "waiting_for_data"}) {
      learner += Number(fields, std::string("learner_") + phase);
    }
    for (const char* phase : {"inference", "physics", "send", "waiting"}) {
      actor += Number(fields, std::string("actor_") + phase);
    }
    EXPECT_NEAR(learner, 100.0, 0.5);
    EXPECT_NEAR(actor, 100.0, 0.5);
    EXPECT_GT(Number(fields, "learner_optimisation"), 0.0);
    EXPECT_GT(Number(fields, "actor_physics"), 0.0);
  }
  // Only the benchmark's RESULT lines: the run's own went to its log.
  EXPECT_THAT(outcome.out, Not(HasSubstr("mean_return=")));
}

// A2C's limit counts one pass of vantage's own A2C update per env step.
TEST(BenchCommandsTest, TrainTimesA2cAgainstItsOwnUpdate) {
  const Outcome outcome = RunVantage(
      "bench train --env=InvertedPendulum --algo=a2c --steps=20480 --sync");
  ASSERT_EQ(outcome.exit_code, 0) << outcome.err;
  const auto fields = ResultFields(outcome.out, "RESULT train ");
  EXPECT_EQ(fields.at("algo"), "a2c");
  EXPECT_EQ(fields.at("sync"), "1");
  ExpectTheLimitOf(fields, "a2c_update_samples_per_s", 1);
  EXPECT_GT(Number(fields, "sps"), 0);
  EXPECT_EQ(fields.count("bare_samples_per_s"), 0u);
}

TEST(BenchCommandsTest, TrainRefusesWhatItCannotTime) {
  const Outcome resume = RunVantage("bench train --run_dir=/tmp/x");
  EXPECT_EQ(resume.exit_code, 2);
  EXPECT_THAT(resume.err, HasSubstr("not for a benchmark"));
  const Outcome trpo = RunVantage("bench train --algo=trpo");
  EXPECT_EQ(trpo.exit_code, 2);
  EXPECT_THAT(trpo.err, HasSubstr("--algo=ppo"));
  const Outcome lagged_sync =
      RunVantage("bench train --sync --max_policy_lag=1");
  EXPECT_EQ(lagged_sync.exit_code, 2);
  EXPECT_THAT(lagged_sync.err, HasSubstr("--max_policy_lag"));
  EXPECT_THAT(lagged_sync.err, HasSubstr("--sync"));
}

// A learner on frames (16 x 128 of 3 x 42 x 42: 43 MB a batch, one update)
// keeps freed memory, and its run's page faults fall with it; the CPU times
// are for docs/benchmarks.md.
TEST(BenchCommandsTest, MallocRunsTheSameRunWithAndWithoutGlibcsDefaults) {
  const Outcome outcome = RunVantage(
      "bench malloc --envs=16 --horizon=128 --steps=2048 "
      "--trpo_zero_baseline");
  ASSERT_EQ(outcome.exit_code, 0) << outcome.err;
  const auto fields = ResultFields(outcome.out, "RESULT malloc ");
  EXPECT_EQ(fields.at("env"), "FirstPersonMaze");
  EXPECT_LT(Number(fields, "kept_faults"), Number(fields, "glibc_faults") / 4);
  EXPECT_GT(Number(fields, "kept_faults"), 0);
  EXPECT_NEAR(Number(fields, "ratio"),
              Number(fields, "glibc_cpu_s") / Number(fields, "kept_cpu_s"),
              0.01 * Number(fields, "ratio") + 0.01);

  const Outcome small = RunVantage("bench malloc --env=Hopper");
  EXPECT_EQ(small.exit_code, 2);
  EXPECT_THAT(small.err, HasSubstr("below glibc's largest mmap threshold"));
  setenv("MALLOC_MMAP_MAX_", "65536", 1);
  const Outcome told = RunVantage("bench malloc");
  unsetenv("MALLOC_MMAP_MAX_");
  EXPECT_EQ(told.exit_code, 2);
  EXPECT_THAT(told.err, HasSubstr("unset MALLOC_MMAP_MAX_"));
}

// A real learner process with connected actors against its idle self: each
// open stream holds a server thread, so the threads grow with the actors.
TEST(BenchCommandsTest, ConnectionsMeasureALearnerPerConnectedActor) {
  const Outcome outcome = RunVantage("bench connections --bench_clients=8");
  ASSERT_EQ(outcome.exit_code, 0) << outcome.err;
  const auto fields = ResultFields(outcome.out, "RESULT connections ");
  EXPECT_EQ(fields.at("actors"), "8");
  EXPECT_GT(Number(fields, "idle_rss_mb"), 0);
  EXPECT_GT(Number(fields, "rss_mb"), 0);
  EXPECT_GE(Number(fields, "threads"), Number(fields, "idle_threads") + 8);
  EXPECT_NEAR(
      Number(fields, "per_actor_kb"),
      (Number(fields, "rss_mb") - Number(fields, "idle_rss_mb")) * 1024 / 8,
      0.1 * 1024 / 8);  // the MB figures are printed to 0.1
}

}  // namespace
}  // namespace vantage
