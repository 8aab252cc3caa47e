// Save/restore of environments, vectors of them and actor cores: a restored
// object must continue bit for bit like the one that was saved, and a bad
// blob must be refused without changing anything.

#include <ATen/ATen.h>
#include <mujoco/mjxmacro.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "actor/actor_core.h"
#include "actor/envs/env_registry.h"
#include "actor/envs/mujoco/mujoco_env.h"
#include "actor/vector_env.h"
#include "common/env/time_limit.h"
#include "common/rollout/segment.h"
#include "common/util/state_bytes.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/fakes/random_discrete_action.h"

namespace vantage {
namespace {

using ::testing::HasSubstr;

std::unique_ptr<Environment> Make(const std::string& name) {
  absl::StatusOr<std::unique_ptr<Environment>> env = MakeEnvironment(name);
  EXPECT_TRUE(env.ok()) << env.status();
  return env.ok() ? std::move(*env) : nullptr;
}

std::unique_ptr<VectorEnv> MakeVector(const std::string& name, int count,
                                      uint64_t seed) {
  absl::StatusOr<std::unique_ptr<VectorEnv>> envs =
      VectorEnv::Create(name, count, seed);
  EXPECT_TRUE(envs.ok()) << envs.status();
  if (!envs.ok()) return nullptr;
  EXPECT_TRUE((*envs)->Reset().ok());
  return std::move(*envs);
}

std::string Save(const Environment& env) {
  absl::StatusOr<std::string> state = env.SaveState();
  EXPECT_TRUE(state.ok()) << state.status();
  return state.ok() ? *state : "";
}

std::string Save(const VectorEnv& envs) {
  absl::StatusOr<std::string> state = envs.SaveState();
  EXPECT_TRUE(state.ok()) << state.status();
  return state.ok() ? *state : "";
}

std::string Save(const ActorCore& actor) {
  absl::StatusOr<std::string> state = actor.SaveState();
  EXPECT_TRUE(state.ok()) << state.status();
  return state.ok() ? *state : "";
}

// Exact comparison of the bits (so -0.0 != 0.0 and NaNs compare), with the
// first difference reported instead of two huge vectors.
void ExpectBitIdentical(const std::vector<double>& expected,
                        const std::vector<double>& actual,
                        const std::string& what) {
  ASSERT_EQ(expected.size(), actual.size()) << what;
  for (size_t i = 0; i < expected.size(); ++i) {
    if (std::memcmp(&expected[i], &actual[i], sizeof(double)) != 0) {
      ADD_FAILURE() << what << ": first difference at value " << i << " of "
                    << expected.size() << ": " << expected[i]
                    << " != " << actual[i];
      return;
    }
  }
}

// `masks`: masked actions' legal choices, action_size bytes per env (null:
// all are legal).
std::vector<double> RandomActions(const EnvSpec& spec, int count,
                                  std::mt19937_64& rng,
                                  const uint8_t* masks = nullptr) {
  std::vector<double> actions;
  for (int n = 0; n < count; ++n) {
    if (spec.discrete) {
      const std::vector<double> action = RandomDiscreteAction(
          spec, masks == nullptr ? nullptr : masks + n * spec.action_size, rng);
      actions.insert(actions.end(), action.begin(), action.end());
      continue;
    }
    for (int64_t i = 0; i < spec.action_size; ++i) {
      const bool bounded = std::isfinite(spec.action_low[i]) &&
                           std::isfinite(spec.action_high[i]);
      // Past the bounds too, so that clipping is exercised.
      const double low = bounded ? 1.5 * spec.action_low[i] : -1.0;
      const double high = bounded ? 1.5 * spec.action_high[i] : 1.0;
      actions.push_back(std::uniform_real_distribution<double>(low, high)(rng));
    }
  }
  return actions;
}

// Drives one environment with seeded random actions, resetting it with a
// seeded seed whenever an episode ends; copying a driver copies everything
// the rest of the run depends on.
struct Driver {
  std::mt19937_64 actions{1};
  std::mt19937_64 reset_seeds{2};
  bool needs_reset = true;
  StepResult last;

  // Everything the environment returns over `steps` steps.
  std::vector<double> Run(Environment& env, int steps) {
    std::vector<double> trace;
    std::vector<double> observation(env.spec().observation_size);
    for (int t = 0; t < steps; ++t) {
      if (needs_reset) {
        const absl::Status status =
            env.Reset(reset_seeds(), absl::MakeSpan(observation));
        EXPECT_TRUE(status.ok()) << status;
        trace.push_back(-12345.0);  // marks the reset in the trace
        trace.insert(trace.end(), observation.begin(), observation.end());
        needs_reset = false;
      }
      const absl::StatusOr<std::vector<uint8_t>> mask = ReadActionMask(env);
      absl::StatusOr<StepResult> result = env.Step(
          RandomActions(env.spec(), 1, actions,
                        mask.ok() && !mask->empty() ? mask->data() : nullptr),
          absl::MakeSpan(observation));
      EXPECT_TRUE(result.ok()) << result.status();
      if (!result.ok()) break;
      last = *result;
      trace.insert(trace.end(), observation.begin(), observation.end());
      trace.push_back(result->reward);
      trace.push_back(result->terminated);
      trace.push_back(result->truncated);
      needs_reset = result->terminated || result->truncated;
    }
    return trace;
  }
};

// Writes a sliding, hopping box whose episodes the time limit cuts after
// `max_steps` steps; `spin` adds a third joint (which changes the model's
// sizes) and `gear` is the x motor's.
void WriteBox(const std::string& path, int max_steps, bool spin, int gear) {
  std::ofstream(path) << absl::StrCat(
      R"xml(
<mujoco model="box">
  <option timestep="0.01"/>
  <custom>
    <text name="vantage_forward_body" data="box"/>
    <numeric name="vantage_max_steps" data=")xml",
      max_steps, R"xml("/>
  </custom>
  <worldbody>
    <geom name="floor" type="plane" size="10 10 1"/>
    <body name="box" pos="0 0 0.5">
      <joint name="x" type="slide" axis="1 0 0"/>
      <joint name="z" type="slide" axis="0 0 1"/>)xml",
      spin ? R"xml(
      <joint name="spin" type="hinge" axis="0 0 1"/>)xml"
           : "",
      R"xml(
      <geom type="box" size="0.1 0.1 0.1" mass="1"/>
    </body>
  </worldbody>
  <actuator>
    <motor joint="x" gear=")xml",
      gear, R"xml(" ctrllimited="true" ctrlrange="-1 1"/>
    <motor joint="z" gear="40" ctrllimited="true" ctrlrange="-1 1"/>
  </actuator>
</mujoco>)xml");
}

// The env name of a WriteBox model with the default joints and gear.
std::string ShortBox(int max_steps) {
  const std::string path = absl::StrCat(
      ::testing::TempDir(), "/vantage_state_box_", max_steps, ".xml");
  WriteBox(path, max_steps, /*spin=*/false, /*gear=*/10);
  return "mjcf:" + path;
}

// The fields of a blob written by StateWriter, and the blob rebuilt from
// them, for crafting blobs that are well formed on the outside only.
std::vector<std::string> Fields(const std::string& blob,
                                const std::string& kind) {
  StateReader reader(blob, kind, 1, "test");
  std::vector<std::string> fields;
  while (reader.status().ok() && !reader.AtEnd()) {
    fields.emplace_back(reader.GetBytes("field"));
  }
  EXPECT_TRUE(reader.Finish().ok()) << reader.status();
  return fields;
}

std::string Rebuild(const std::vector<std::string>& fields,
                    const std::string& kind) {
  StateWriter writer(kind, 1);
  for (const std::string& field : fields) writer.PutBytes(field);
  return std::move(writer).Finish();
}

// ---------------------------------------------------------------------------
// Single environments

class EnvReplayTest : public ::testing::TestWithParam<std::string> {};

TEST_P(EnvReplayTest, RestoredEnvReplaysBitIdentically) {
  const std::string name = GetParam();
  const auto env = Make(name);
  ASSERT_NE(env, nullptr);
  Driver driver;
  driver.Run(*env, 50);
  const std::string state = Save(*env);
  const Driver at_save = driver;
  const std::vector<double> expected = driver.Run(*env, 200);

  // Into a fresh environment, and into one that has run other episodes.
  for (const bool dirty : {false, true}) {
    const auto restored = Make(name);
    ASSERT_NE(restored, nullptr);
    if (dirty) {
      Driver other;
      other.actions.seed(77);
      other.reset_seeds.seed(78);
      other.Run(*restored, 30);
    }
    const absl::Status status = restored->RestoreState(state);
    ASSERT_TRUE(status.ok()) << status;
    // Nothing is lost or added on the way: saving again gives the blob.
    EXPECT_EQ(Save(*restored), state) << name;
    Driver replay = at_save;
    ExpectBitIdentical(expected, replay.Run(*restored, 200),
                       absl::StrCat(name, dirty ? " (dirty)" : " (fresh)"));
  }
}

// A state saved before the first episode (a checkpoint of an actor that
// has not stepped yet) restores, and the restored environment then runs
// exactly like the saved one.
TEST_P(EnvReplayTest, AStateSavedBeforeAnyEpisodeRestores) {
  const std::string name = GetParam();
  const auto env = Make(name);
  const auto restored = Make(name);
  ASSERT_NE(env, nullptr);
  ASSERT_NE(restored, nullptr);
  const std::string state = Save(*env);
  const absl::Status status = restored->RestoreState(state);
  ASSERT_TRUE(status.ok()) << status;
  EXPECT_EQ(Save(*restored), state) << name;
  Driver a, b;
  ExpectBitIdentical(a.Run(*env, 100), b.Run(*restored, 100), name);
}

INSTANTIATE_TEST_SUITE_P(AllEnvs, EnvReplayTest,
                         ::testing::ValuesIn(RegisteredEnvironments()),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           return info.param;
                         });

// The replay test above runs on whatever the registry holds; this only
// makes sure that no suite has dropped out of it (a new task changes no
// test).
TEST(EnvStateTest, EverySuiteIsRegistered) {
  EXPECT_THAT(RegisteredEnvironments(),
              ::testing::IsSupersetOf({"HalfCheetah", "BulletHopper",
                                       "TerrainBipedFlat", "MinAtarBreakout",
                                       "TwoDMaze", "FirstPersonMaze"}));
}

// The state is the whole mjData buffer: check that in MuJoCo 2.2.2 every
// array the environments (and the next step) read lives inside it. (The
// Bullet environments save a replay log instead.)
TEST(EnvStateTest, EveryMjDataArrayLivesInTheBuffer) {
  int mujoco_envs = 0;
  for (const std::string& name : RegisteredEnvironments()) {
    const auto env = Make(name);
    ASSERT_NE(env, nullptr);
    const auto* time_limit = dynamic_cast<const TimeLimit*>(env.get());
    ASSERT_NE(time_limit, nullptr) << name;
    const auto* mujoco = dynamic_cast<const MujocoEnv*>(&time_limit->inner());
    if (mujoco == nullptr) continue;
    ++mujoco_envs;
    const mjModel* m = mujoco->model();
    const mjData* d = mujoco->data();
    const char* begin = static_cast<const char*>(d->buffer);
    const char* end = begin + d->nbuffer;
    MJDATA_POINTERS_PREAMBLE(m)
    int arrays = 0;
#define X(type, field, rows, cols)                                             \
  {                                                                            \
    const char* p = reinterpret_cast<const char*>(d->field);                   \
    const size_t bytes = sizeof(type) * static_cast<size_t>(m->rows) * (cols); \
    EXPECT_TRUE(p >= begin && p + bytes <= end) << name << ": " #field;        \
    ++arrays;                                                                  \
  }
    MJDATA_POINTERS
#undef X
    EXPECT_EQ(arrays, 100);  // all of MJDATA_POINTERS
    (void)nv;
    (void)njmax;
  }
  EXPECT_EQ(mujoco_envs, 11);
}

// Saving exactly when an episode has ended (the time limit refuses to step
// until a reset) and continuing from there.
void ExpectSaveAtEpisodeEndReplays(const std::string& name, bool truncated) {
  const auto env = Make(name);
  ASSERT_NE(env, nullptr);
  Driver driver;
  bool ended = false;
  for (int t = 0; t < 2000 && !ended; ++t) {
    driver.Run(*env, 1);
    ended = driver.needs_reset;
  }
  ASSERT_TRUE(ended) << name;
  ASSERT_EQ(driver.last.truncated, truncated) << name;
  const std::string state = Save(*env);
  const int64_t elapsed = dynamic_cast<TimeLimit&>(*env).elapsed_steps();
  const Driver at_save = driver;
  std::vector<double> observation(env->spec().observation_size);
  EXPECT_EQ(env->Step(RandomActions(env->spec(), 1, driver.actions),
                      absl::MakeSpan(observation))
                .status()
                .code(),
            absl::StatusCode::kFailedPrecondition);
  driver = at_save;
  const std::vector<double> expected = driver.Run(*env, 100);

  const auto restored = Make(name);
  ASSERT_TRUE(restored->RestoreState(state).ok());
  EXPECT_EQ(dynamic_cast<TimeLimit&>(*restored).elapsed_steps(), elapsed);
  Driver replay = at_save;
  EXPECT_EQ(restored
                ->Step(RandomActions(restored->spec(), 1, replay.actions),
                       absl::MakeSpan(observation))
                .status()
                .code(),
            absl::StatusCode::kFailedPrecondition);
  replay = at_save;
  ExpectBitIdentical(expected, replay.Run(*restored, 100), name);
}

TEST(EnvStateTest, SavedRightAfterTermination) {
  // Random actions topple the pendulum within a few dozen steps.
  ExpectSaveAtEpisodeEndReplays("InvertedPendulum", /*truncated=*/false);
}

TEST(EnvStateTest, SavedRightAfterTruncation) {
  ExpectSaveAtEpisodeEndReplays(ShortBox(7), /*truncated=*/true);
}

TEST(EnvStateTest, SavedBeforeTheFirstReset) {
  const auto env = Make("Hopper");
  const std::string state = Save(*env);
  const auto restored = Make("Hopper");
  Driver driver;
  driver.Run(*restored, 20);
  ASSERT_TRUE(restored->RestoreState(state).ok());
  std::vector<double> observation(11);
  EXPECT_EQ(
      restored->Step({0, 0, 0}, absl::MakeSpan(observation)).status().code(),
      absl::StatusCode::kFailedPrecondition);
  EXPECT_EQ(Save(*restored), state);
}

// ---------------------------------------------------------------------------
// Bad blobs

// `env` refuses `blob` (InvalidArgument, the message containing `message`)
// and saves the same state as before.
void ExpectRefusedAndUnchanged(Environment& env, const std::string& blob,
                               const std::string& message) {
  const std::string before = Save(env);
  const absl::Status status = env.RestoreState(blob);
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument) << status;
  EXPECT_THAT(status.message(), HasSubstr(message));
  EXPECT_EQ(Save(env), before) << message;
}

class BadEnvStateTest : public ::testing::Test {
 protected:
  void SetUp() override {
    env_ = Make("HalfCheetah");
    twin_ = Make("HalfCheetah");
    driver_.Run(*env_, 25);
    twin_driver_.Run(*twin_, 25);
    state_ = Save(*env_);
  }
  void TearDown() override {
    // Still stepping exactly like the twin that never saw a bad blob.
    ExpectBitIdentical(twin_driver_.Run(*twin_, 60), driver_.Run(*env_, 60),
                       "after refused blobs");
  }

  std::unique_ptr<Environment> env_;
  std::unique_ptr<Environment> twin_;
  Driver driver_;
  Driver twin_driver_;
  std::string state_;
};

TEST_F(BadEnvStateTest, TruncatedBlobsAreRefused) {
  for (size_t size :
       {size_t{0}, size_t{1}, size_t{8}, size_t{20}, size_t{27}, size_t{28},
        state_.size() / 2, state_.size() - 8, state_.size() - 1}) {
    ExpectRefusedAndUnchanged(*env_, state_.substr(0, size), "truncated");
  }
  ExpectRefusedAndUnchanged(*env_, state_ + "x", "stray bytes");
}

TEST_F(BadEnvStateTest, GarbageIsRefused) {
  ExpectRefusedAndUnchanged(*env_, "certainly not a state",
                            "not a saved state");
  std::mt19937_64 rng(3);
  std::string noise(state_.size(), '\0');
  for (char& c : noise) c = static_cast<char>(rng());
  ExpectRefusedAndUnchanged(*env_, noise, "not a saved state");
  // One flipped bit in the physics buffer keeps every size right.
  std::string flipped = state_;
  flipped[flipped.size() / 2] ^= 0x10;
  ExpectRefusedAndUnchanged(*env_, flipped, "checksum mismatch");
}

TEST_F(BadEnvStateTest, StatesOfOtherEnvsAndKindsAreRefused) {
  const auto hopper = Make("Hopper");
  Driver driver;
  driver.Run(*hopper, 10);
  ExpectRefusedAndUnchanged(*env_, Save(*hopper),
                            "the environment is 'Hopper' in the state but "
                            "'HalfCheetah' here");
  // The same dynamics under another name.
  const auto sparse = Make("SparseHalfCheetah");
  Driver sparse_driver;
  sparse_driver.Run(*sparse, 10);
  ExpectRefusedAndUnchanged(*env_, Save(*sparse), "SparseHalfCheetah");
  const auto envs = MakeVector("HalfCheetah", 2, 0);
  ExpectRefusedAndUnchanged(*env_, Save(*envs),
                            "holds a 'vector_env' state, not a 'time_limit'");
}

TEST_F(BadEnvStateTest, InnerStateIsCheckedBeforeTheTimeLimitChanges) {
  // A HalfCheetah time-limit envelope around Hopper physics: the time limit
  // accepts its own fields, the physics refuse theirs.
  const auto hopper = Make("Hopper");
  Driver driver;
  driver.Run(*hopper, 3);
  std::vector<std::string> fields = Fields(state_, "time_limit");
  ASSERT_EQ(fields.size(), 5u);
  EXPECT_EQ(Rebuild(fields, "time_limit"), state_);
  fields.back() = Fields(Save(*hopper), "time_limit").back();
  const int64_t other_elapsed = 3;
  std::memcpy(fields[2].data(), &other_elapsed, sizeof(other_elapsed));
  ExpectRefusedAndUnchanged(*env_, Rebuild(fields, "time_limit"),
                            "HalfCheetah: MuJoCo state: the environment is "
                            "'Hopper'");
  // An elapsed step count past the limit.
  fields = Fields(state_, "time_limit");
  int64_t elapsed = 5000;
  std::memcpy(fields[2].data(), &elapsed, sizeof(elapsed));
  ExpectRefusedAndUnchanged(*env_, Rebuild(fields, "time_limit"),
                            "elapsed_steps 5000 is impossible");
}

TEST(EnvStateTest, StatesOfOtherModelsAreRefused) {
  // Another MJCF file: another name.
  const auto a = Make(ShortBox(7));
  const auto b = Make(ShortBox(9));
  Driver driver;
  driver.Run(*a, 3);
  const std::string state = Save(*a);
  absl::Status status = b->RestoreState(state);
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(status.message(), HasSubstr("vantage_state_box_7"));
  // The same file, edited between save and restore: same name, but the
  // physics buffer's layout no longer fits.
  const std::string path =
      absl::StrCat(::testing::TempDir(), "/vantage_state_box_edited.xml");
  WriteBox(path, 7, /*spin=*/false, /*gear=*/10);
  const auto before = Make("mjcf:" + path);
  Driver other_driver;
  other_driver.Run(*before, 3);
  const std::string before_state = Save(*before);
  // The same file again is fine.
  EXPECT_TRUE(Make("mjcf:" + path)->RestoreState(before_state).ok());
  WriteBox(path, 7, /*spin=*/true, /*gear=*/10);
  const auto spinning = Make("mjcf:" + path);
  const std::string spinning_state = Save(*spinning);
  status = spinning->RestoreState(before_state);
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(status.message(), HasSubstr("nq is 2 in the state but 3 here"));
  EXPECT_EQ(Save(*spinning), spinning_state);
  // Every size the same, only a gear changed.
  WriteBox(path, 7, /*spin=*/false, /*gear=*/20);
  const auto geared = Make("mjcf:" + path);
  const std::string geared_state = Save(*geared);
  status = geared->RestoreState(before_state);
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(status.message(), HasSubstr("saved with another MuJoCo model"));
  EXPECT_EQ(Save(*geared), geared_state);
}

class FakeEnv : public Environment {
 public:
  FakeEnv() { spec_.name = "Fake"; }
  const EnvSpec& spec() const override { return spec_; }
  absl::Status Reset(uint64_t, absl::Span<double>) override {
    return absl::OkStatus();
  }
  absl::StatusOr<StepResult> Step(absl::Span<const double>,
                                  absl::Span<double>) override {
    return StepResult();
  }

 private:
  EnvSpec spec_;
};

TEST(EnvStateTest, EnvironmentsWithoutStateSaySo) {
  FakeEnv fake;
  EXPECT_EQ(fake.SaveState().status().code(), absl::StatusCode::kUnimplemented);
  EXPECT_THAT(fake.SaveState().status().message(), HasSubstr("Fake"));
  EXPECT_EQ(fake.RestoreState("x").code(), absl::StatusCode::kUnimplemented);
  TimeLimit limited(std::make_unique<FakeEnv>());
  EXPECT_EQ(limited.SaveState().status().code(),
            absl::StatusCode::kUnimplemented);
}

// ---------------------------------------------------------------------------
// Vectors of environments

struct VectorTrace {
  std::vector<double> values;
  std::vector<double> finished;
};

// Steps `envs` with actions from `rng`, recording everything they expose.
VectorTrace RunVector(VectorEnv& envs, std::mt19937_64& rng, int steps) {
  VectorTrace trace;
  for (int t = 0; t < steps; ++t) {
    const absl::Status status = envs.Step(RandomActions(
        envs.spec(), envs.size(), rng,
        envs.action_masks().empty() ? nullptr : envs.action_masks().data()));
    EXPECT_TRUE(status.ok()) << status;
    auto& v = trace.values;
    v.insert(v.end(), envs.observations().begin(), envs.observations().end());
    v.insert(v.end(), envs.rewards().begin(), envs.rewards().end());
    v.insert(v.end(), envs.terminated().begin(), envs.terminated().end());
    v.insert(v.end(), envs.truncated().begin(), envs.truncated().end());
    for (const FinishedEpisode& episode : envs.finished()) {
      const int64_t obs = envs.spec().observation_size;
      const double* final_obs =
          envs.final_observations().data() + episode.env_index * obs;
      v.insert(v.end(), final_obs, final_obs + obs);
      trace.finished.insert(
          trace.finished.end(),
          {static_cast<double>(t), static_cast<double>(episode.env_index),
           episode.episode_return, static_cast<double>(episode.length),
           static_cast<double>(episode.truncated)});
    }
  }
  return trace;
}

std::vector<double> Exposed(const VectorEnv& envs) {
  std::vector<double> v(envs.observations().begin(), envs.observations().end());
  v.insert(v.end(), envs.final_observations().begin(),
           envs.final_observations().end());
  v.insert(v.end(), envs.rewards().begin(), envs.rewards().end());
  v.insert(v.end(), envs.terminated().begin(), envs.terminated().end());
  v.insert(v.end(), envs.truncated().begin(), envs.truncated().end());
  for (const FinishedEpisode& episode : envs.finished()) {
    v.insert(v.end(),
             {static_cast<double>(episode.env_index), episode.episode_return,
              static_cast<double>(episode.length),
              static_cast<double>(episode.truncated)});
  }
  return v;
}

// Steps 3 envs `before` times (or until an episode has just ended, if
// `save_at_episode_end`), saves, and checks that a vector created with
// another seed and stepped elsewhere replays the next 200 steps once
// restored.
void ExpectVectorReplays(const std::string& name, int before,
                         bool save_at_episode_end) {
  const auto envs = MakeVector(name, 3, 1);
  ASSERT_NE(envs, nullptr);
  std::mt19937_64 rng(4);
  for (int t = 0; t < before ||
                  (save_at_episode_end && t < 2000 && envs->finished().empty());
       ++t) {
    RunVector(*envs, rng, 1);
  }
  if (save_at_episode_end) {
    ASSERT_FALSE(envs->finished().empty()) << name;
  }
  const std::string state = Save(*envs);
  const std::vector<double> exposed = Exposed(*envs);
  const std::mt19937_64 at_save = rng;
  const VectorTrace expected = RunVector(*envs, rng, 200);
  EXPECT_FALSE(expected.finished.empty()) << "no episode ended in " << name;

  const auto restored = MakeVector(name, 3, 99);
  std::mt19937_64 other(5);
  RunVector(*restored, other, 13);
  const absl::Status status = restored->RestoreState(state);
  ASSERT_TRUE(status.ok()) << status;
  ExpectBitIdentical(exposed, Exposed(*restored), name + " right after");
  EXPECT_EQ(Save(*restored), state);
  std::mt19937_64 replay = at_save;
  const VectorTrace actual = RunVector(*restored, replay, 200);
  ExpectBitIdentical(expected.values, actual.values, name);
  ExpectBitIdentical(expected.finished, actual.finished, name + " episodes");
}

TEST(VectorEnvStateTest, RestoredVectorReplaysWithAutoReset) {
  ExpectVectorReplays("InvertedPendulum", 30, false);
  ExpectVectorReplays("Hopper", 30, false);
}

TEST(VectorEnvStateTest, SavedInTheStepThatEndedEpisodes) {
  ExpectVectorReplays("InvertedPendulum", 0, true);
  // Truncations every 5 steps.
  ExpectVectorReplays(ShortBox(5), 3, true);
}

TEST(VectorEnvStateTest, BadStatesChangeNothing) {
  const auto envs = MakeVector("HalfCheetah", 3, 1);
  const auto twin = MakeVector("HalfCheetah", 3, 1);
  std::mt19937_64 rng(6);
  std::mt19937_64 twin_rng(6);
  RunVector(*envs, rng, 10);
  RunVector(*twin, twin_rng, 10);
  const std::string before = Save(*envs);

  // A well-formed state from another run, whose last environment carries
  // Hopper physics: envs 0 and 1 take theirs before env 2 refuses, and
  // must be rolled back.
  const auto other = MakeVector("HalfCheetah", 3, 2);
  std::mt19937_64 other_rng(7);
  RunVector(*other, other_rng, 20);
  const auto hopper = MakeVector("Hopper", 1, 0);
  std::vector<std::string> fields = Fields(Save(*other), "vector_env");
  fields.back() = Fields(Save(*hopper), "vector_env").back();
  std::vector<std::string> blobs = {Rebuild(fields, "vector_env")};
  std::vector<std::string> messages = {
      "env 2: HalfCheetah: time limit state: "
      "the environment is 'Hopper'"};
  blobs.push_back(Save(*hopper));
  messages.push_back("the environment is 'Hopper' in the state");
  blobs.push_back(Save(*MakeVector("HalfCheetah", 2, 1)));
  messages.push_back("the number of environments is 2 in the state but 3");
  blobs.push_back(before.substr(0, before.size() - 3));
  messages.push_back("truncated");
  blobs.push_back(Save(*Make("HalfCheetah")));
  messages.push_back("holds a 'time_limit' state, not a 'vector_env'");
  for (size_t i = 0; i < blobs.size(); ++i) {
    const absl::Status status = envs->RestoreState(blobs[i]);
    EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument) << status;
    EXPECT_THAT(status.message(), HasSubstr(messages[i]));
    EXPECT_EQ(Save(*envs), before) << messages[i];
  }
  ExpectBitIdentical(RunVector(*twin, twin_rng, 50).values,
                     RunVector(*envs, rng, 50).values, "after refused blobs");
}

// ---------------------------------------------------------------------------
// Actor cores

ActorConfig Config(const std::string& env) {
  ActorConfig config;
  config.env = env;
  config.num_envs = 3;
  config.segment_length = 40;
  config.seed = 5;
  config.actor_id = 2;
  config.network.hidden = {16};
  return config;
}

// The weights of a learner's freshly initialised policy.
PolicyWeights InitialWeights(const EnvSpec& spec) {
  at::manual_seed(11);
  PolicyNetwork policy(spec, Config(spec.name).network);
  return ExportPolicyWeights(*policy, RunningMeanStd(spec.observation_size),
                             /*version=*/4);
}

std::unique_ptr<ActorCore> MakeActor(const ActorConfig& config) {
  absl::StatusOr<std::unique_ptr<ActorCore>> actor = ActorCore::Create(config);
  EXPECT_TRUE(actor.ok()) << actor.status();
  if (!actor.ok()) return nullptr;
  const absl::Status status =
      (*actor)->SetWeights(InitialWeights((*actor)->spec()));
  EXPECT_TRUE(status.ok()) << status;
  return std::move(*actor);
}

std::vector<Segment> Collect(ActorCore& actor, int rounds) {
  SegmentQueue queue(64);
  for (int round = 0; round < rounds; ++round) {
    const absl::Status status = actor.CollectSegments(queue);
    EXPECT_TRUE(status.ok()) << status;
  }
  queue.Close();
  std::vector<Segment> segments;
  while (true) {
    absl::StatusOr<Segment> segment = queue.Receive();
    if (!segment.ok()) break;
    segments.push_back(std::move(*segment));
  }
  return segments;
}

void ExpectSameSegments(const std::vector<Segment>& expected,
                        const std::vector<Segment>& actual) {
  ASSERT_EQ(expected.size(), actual.size());
  for (size_t i = 0; i < expected.size(); ++i) {
    const Segment& a = expected[i];
    const Segment& b = actual[i];
    SCOPED_TRACE(absl::StrCat("segment ", i));
    EXPECT_EQ(a.actor_id, b.actor_id);
    EXPECT_EQ(a.env_slot, b.env_slot);
    EXPECT_EQ(a.sequence, b.sequence);
    EXPECT_EQ(a.policy_version, b.policy_version);
    EXPECT_TRUE(at::equal(a.observations, b.observations));
    EXPECT_TRUE(at::equal(a.actions, b.actions));
    EXPECT_TRUE(at::equal(a.rewards, b.rewards));
    EXPECT_TRUE(at::equal(a.terminated, b.terminated));
    EXPECT_TRUE(at::equal(a.truncated, b.truncated));
    EXPECT_TRUE(at::equal(a.final_observations, b.final_observations));
    EXPECT_TRUE(at::equal(a.behaviour_log_probs, b.behaviour_log_probs));
    EXPECT_EQ(a.episode_returns, b.episode_returns);
    EXPECT_EQ(a.episode_lengths, b.episode_lengths);
  }
}

void ExpectActorReplays(const ActorConfig& config) {
  const auto actor = MakeActor(config);
  ASSERT_NE(actor, nullptr);
  Collect(*actor, 2);
  const std::string state = Save(*actor);
  const int64_t env_steps = actor->env_steps();
  const std::vector<Segment> expected = Collect(*actor, 3);
  int episodes = 0;
  for (const Segment& segment : expected) {
    episodes += static_cast<int>(segment.episode_returns.size());
  }
  EXPECT_GT(episodes, 0) << config.env;

  // Same config and weights, but it has acted on its own before.
  const auto restored = MakeActor(config);
  ASSERT_NE(restored, nullptr);
  Collect(*restored, 1);
  const absl::Status status = restored->RestoreState(state);
  ASSERT_TRUE(status.ok()) << status;
  EXPECT_EQ(restored->env_steps(), env_steps);
  EXPECT_EQ(Save(*restored), state);
  ExpectSameSegments(expected, Collect(*restored, 3));
  EXPECT_EQ(restored->env_steps(), actor->env_steps());
}

TEST(ActorStateTest, RestoredActorCollectsTheSameSegments) {
  ExpectActorReplays(Config("InvertedPendulum"));
}

TEST(ActorStateTest, RestoredActorCollectsTheSameSegmentsWithTruncations) {
  ActorConfig config = Config(ShortBox(15));
  config.segment_length = 16;
  ExpectActorReplays(config);
}

TEST(ActorStateTest, BadStatesChangeNothing) {
  const ActorConfig config = Config("InvertedPendulum");
  const auto actor = MakeActor(config);
  const auto twin = MakeActor(config);
  Collect(*actor, 1);
  Collect(*twin, 1);
  const std::string before = Save(*actor);

  // Another actor's (well-formed) state whose environments are a vector of
  // the wrong size: the sampling generator must not have moved when the
  // environments refuse.
  const auto other = MakeActor(config);
  Collect(*other, 2);
  std::vector<std::string> fields = Fields(Save(*other), "actor_core");
  auto pair = MakeVector("InvertedPendulum", 2, 0);
  fields.back() = Save(*pair);
  std::vector<std::pair<std::string, std::string>> cases = {
      {Rebuild(fields, "actor_core"),
       "the number of environments is 2 in the state but 3"},
      {before.substr(0, 100), "truncated"},
      {"garbage", "not a saved state"},
      {Save(*MakeVector("InvertedPendulum", 3, 0)),
       "holds a 'vector_env' state, not a 'actor_core'"}};
  ActorConfig hopper = Config("Hopper");
  cases.push_back({Save(*MakeActor(hopper)),
                   "the environment is 'Hopper' in the state but "
                   "'InvertedPendulum' here"});
  ActorConfig other_id = config;
  other_id.actor_id = 3;
  cases.push_back(
      {Save(*MakeActor(other_id)), "actor_id is 3 in the state but 2 here"});
  ActorConfig fewer = config;
  fewer.num_envs = 2;
  cases.push_back({Save(*MakeActor(fewer)), "num_envs is 2"});
  // A generator state of the right size that LibTorch refuses.
  fields = Fields(before, "actor_core");
  std::string& generator = fields[5];
  std::fill(generator.begin(), generator.end(), '\xff');
  cases.push_back({Rebuild(fields, "actor_core"), "sampling generator"});
  for (const auto& [blob, message] : cases) {
    const absl::Status status = actor->RestoreState(blob);
    EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument) << status;
    EXPECT_THAT(status.message(), HasSubstr(message));
    EXPECT_EQ(Save(*actor), before) << message;
  }
  ExpectSameSegments(Collect(*twin, 2), Collect(*actor, 2));
}

// ---------------------------------------------------------------------------
// The byte format

TEST(StateBytesTest, FieldsAreCheckedOneByOne) {
  StateWriter writer("thing", 3);
  writer.PutU64(7);
  writer.PutBytes("abc");
  writer.PutDoubles(std::vector<double>{1.0, 2.0});
  const std::string blob = std::move(writer).Finish();

  StateReader good(blob, "thing", 3, "ctx");
  EXPECT_EQ(good.GetU64("a"), 7u);
  EXPECT_EQ(good.GetBytes("b"), "abc");
  EXPECT_EQ(good.GetDoubles("c", 2), (std::vector<double>{1.0, 2.0}));
  EXPECT_TRUE(good.Finish().ok());

  StateReader wrong_size(blob, "thing", 3, "ctx");
  wrong_size.GetBool("a");
  EXPECT_THAT(wrong_size.status().message(),
              HasSubstr("ctx: field 'a' holds 8 bytes, expected 1"));
  // The first error sticks.
  wrong_size.GetU64("b");
  EXPECT_THAT(wrong_size.Finish().message(), HasSubstr("field 'a'"));

  StateReader unread(blob, "thing", 3, "ctx");
  unread.GetU64("a");
  EXPECT_THAT(unread.Finish().message(), HasSubstr("unread fields"));

  StateReader past_end(blob, "thing", 3, "ctx");
  past_end.GetU64("a");
  past_end.GetBytes("b");
  past_end.GetBytes("c");
  past_end.GetU64("d");
  EXPECT_THAT(past_end.status().message(), HasSubstr("ends before field 'd'"));

  EXPECT_THAT(StateReader(blob, "thing", 4, "ctx").status().message(),
              HasSubstr("format version 3"));
  EXPECT_THAT(StateReader(blob, "other", 3, "ctx").status().message(),
              HasSubstr("holds a 'thing' state, not a 'other'"));
}

TEST(StateBytesTest, PackedBytesRoundTrip) {
  std::mt19937_64 rng(8);
  for (size_t size : {0, 5, 8, 64, 1003, 40000}) {
    std::string bytes(size, '\0');
    for (size_t i = 0; i < size; ++i) {
      // Long zero runs, single nonzero bytes inside zero words, dense parts.
      if ((i / 512) % 3 == 1 || rng() % 50 == 0) {
        bytes[i] = static_cast<char>(rng());
      }
    }
    StateWriter writer("packed", 1);
    writer.PutPacked(bytes);
    const std::string blob = std::move(writer).Finish();
    if (size == 40000) {
      EXPECT_LT(blob.size(), size * 3 / 4);
    }
    StateReader reader(blob, "packed", 1, "ctx");
    EXPECT_EQ(reader.GetPacked("p", size), bytes) << size;
    EXPECT_TRUE(reader.Finish().ok()) << reader.status();
    StateReader wrong(blob, "packed", 1, "ctx");
    wrong.GetPacked("p", size + 1);
    EXPECT_THAT(wrong.status().message(),
                HasSubstr(absl::StrCat("unpacks to ", size, " bytes")));
  }
  // Runs past the end, and a zero-length run that would never finish.
  for (const std::vector<uint32_t>& groups :
       {std::vector<uint32_t>{1, 2}, std::vector<uint32_t>{0, 0}}) {
    std::string packed(8, '\0');
    packed[0] = 16;  // 16 bytes: two words
    packed.append(reinterpret_cast<const char*>(groups.data()), 8);
    packed.append(16, 'x');
    StateWriter writer("packed", 1);
    writer.PutBytes(packed);
    StateReader reader(std::move(writer).Finish(), "packed", 1, "ctx");
    reader.GetPacked("p", 16);
    EXPECT_THAT(reader.status().message(),
                HasSubstr("field 'p' is not a packed buffer"));
  }
}

}  // namespace
}  // namespace vantage
