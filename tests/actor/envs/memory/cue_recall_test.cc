// CueRecall's rules: the cue comes from the seed, blank steps follow, the
// recall pays 1 for the cue's action only and ends the episode, and the
// observation that asks is the same whatever the cue (so only memory can
// beat chance); options, bad actions and an exact save and restore.

#include "actor/envs/memory/cue_recall.h"

#include <set>
#include <vector>

#include "actor/envs/env_registry.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace vantage {
namespace {

using ::testing::HasSubstr;

std::unique_ptr<Environment> Make(const std::string& name) {
  absl::StatusOr<std::unique_ptr<Environment>> env = MakeEnvironment(name);
  EXPECT_TRUE(env.ok()) << env.status();
  return env.ok() ? *std::move(env) : nullptr;
}

// The cue an episode shows: the hot entry of its first observation.
int Cue(const std::vector<double>& first, int cues) {
  for (int i = 0; i < cues; ++i) {
    if (first[i] == 1.0) return i;
  }
  return -1;
}

TEST(CueRecallTest, OnlyTheCuesActionAtTheRecallPays) {
  std::unique_ptr<Environment> env = Make("CueRecall:cues=3,delay=4");
  ASSERT_NE(env, nullptr);
  EXPECT_EQ(env->spec().name, "CueRecall:cues=3,delay=4");
  EXPECT_EQ(env->spec().observation_size, 5);
  EXPECT_TRUE(env->spec().discrete);
  EXPECT_EQ(env->spec().action_size, 3);
  std::set<std::vector<double>> recall_observations;
  std::set<int> cues_seen;
  for (uint64_t seed = 0; seed < 30; ++seed) {
    for (int answer = 0; answer < 3; ++answer) {
      std::vector<double> obs(5);
      ASSERT_TRUE(env->Reset(seed, absl::MakeSpan(obs)).ok());
      const int cue = Cue(obs, 3);
      ASSERT_GE(cue, 0);
      EXPECT_EQ(obs[3], 1.0);  // the cue is shown
      cues_seen.insert(cue);
      double total = 0;
      for (int t = 0; t < 5; ++t) {
        const bool recall = t == 4;
        if (t > 0) {
          // Blank, then the question.
          EXPECT_EQ(obs, (std::vector<double>{0, 0, 0, 0, recall ? 1.0 : 0}))
              << "seed " << seed << " step " << t;
        }
        if (recall) recall_observations.insert(obs);
        const double action = recall ? answer : (t % 3);
        absl::StatusOr<StepResult> result =
            env->Step(absl::MakeConstSpan(&action, 1), absl::MakeSpan(obs));
        ASSERT_TRUE(result.ok()) << result.status();
        EXPECT_EQ(result->terminated, recall);
        EXPECT_FALSE(result->truncated);
        total += result->reward;
      }
      EXPECT_EQ(total, answer == cue ? 1.0 : 0.0) << "seed " << seed;
    }
  }
  EXPECT_EQ(cues_seen.size(), 3u);  // every cue comes up
  // The question looks the same whatever the cue: without memory, chance.
  EXPECT_EQ(recall_observations.size(), 1u);
}

TEST(CueRecallTest, WithoutDelayTheCueAndTheQuestionComeTogether) {
  std::unique_ptr<Environment> env = Make("CueRecall:delay=0");
  ASSERT_NE(env, nullptr);
  std::vector<double> obs(6);
  ASSERT_TRUE(env->Reset(7, absl::MakeSpan(obs)).ok());
  const double action = Cue(obs, 4);
  EXPECT_EQ(obs[4], 1.0);
  EXPECT_EQ(obs[5], 1.0);
  absl::StatusOr<StepResult> result =
      env->Step(absl::MakeConstSpan(&action, 1), absl::MakeSpan(obs));
  ASSERT_TRUE(result.ok());
  EXPECT_EQ(result->reward, 1.0);
  EXPECT_TRUE(result->terminated);
}

TEST(CueRecallTest, BadOptionsAndActionsAreRefusedByName) {
  EXPECT_THAT(
      std::string(MakeEnvironment("CueRecall:cues=1").status().message()),
      HasSubstr("cues"));
  EXPECT_THAT(
      std::string(MakeEnvironment("CueRecall:delay=-1").status().message()),
      HasSubstr("delay"));
  std::unique_ptr<Environment> env = Make("CueRecall");
  std::vector<double> obs(6);
  ASSERT_TRUE(env->Reset(1, absl::MakeSpan(obs)).ok());
  const double bad = 4;  // 4 cues: actions 0..3
  EXPECT_FALSE(
      env->Step(absl::MakeConstSpan(&bad, 1), absl::MakeSpan(obs)).ok());
}

TEST(CueRecallTest, ASavedEpisodeGoesOnExactly) {
  std::unique_ptr<Environment> env = Make("CueRecall:delay=3");
  std::vector<double> obs(6);
  ASSERT_TRUE(env->Reset(11, absl::MakeSpan(obs)).ok());
  const int cue = Cue(obs, 4);
  const double wait = 0;
  ASSERT_TRUE(
      env->Step(absl::MakeConstSpan(&wait, 1), absl::MakeSpan(obs)).ok());
  absl::StatusOr<std::string> state = env->SaveState();
  ASSERT_TRUE(state.ok()) << state.status();
  std::unique_ptr<Environment> other = Make("CueRecall:delay=3");
  ASSERT_TRUE(other->RestoreState(*state).ok());
  const double answer = cue;
  for (Environment* e : {env.get(), other.get()}) {
    double total = 0;
    for (int t = 0; t < 3; ++t) {
      const double action = t == 2 ? answer : wait;
      absl::StatusOr<StepResult> result =
          e->Step(absl::MakeConstSpan(&action, 1), absl::MakeSpan(obs));
      ASSERT_TRUE(result.ok()) << result.status();
      total += result->reward;
    }
    EXPECT_EQ(total, 1.0);
  }
  // Another task's state is refused.
  std::unique_ptr<Environment> longer = Make("CueRecall:delay=5");
  EXPECT_FALSE(longer->RestoreState(*state).ok());
}

}  // namespace
}  // namespace vantage
