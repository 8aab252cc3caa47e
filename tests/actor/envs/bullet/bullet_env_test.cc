#include "actor/envs/bullet/bullet_env.h"

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "actor/envs/bullet/biped_walk.h"
#include "actor/envs/bullet/bullet_hopper.h"
#include "actor/envs/env_registry.h"
#include "common/util/state_bytes.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace vantage {
namespace {

using ::testing::HasSubstr;

const char* const kBulletEnvs[] = {"BipedWalkFlat", "BipedWalkIncline",
                                   "BulletHopper"};

std::unique_ptr<Environment> Make(const std::string& name) {
  absl::StatusOr<std::unique_ptr<Environment>> env = MakeEnvironment(name);
  EXPECT_TRUE(env.ok()) << env.status();
  return env.ok() ? std::move(*env) : nullptr;
}

bool BitEqual(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() &&
         (a.empty() ||
          std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0);
}

std::vector<double> RandomAction(const EnvSpec& spec, std::mt19937_64& rng) {
  std::vector<double> action(spec.action_size);
  for (double& a : action) {
    a = std::uniform_real_distribution<double>(-1.0, 1.0)(rng);
  }
  return action;
}

// Everything `steps` random actions produce (observations, rewards, flags),
// resetting with the next seed whenever an episode ends.
struct Driver {
  std::mt19937_64 actions{5};
  uint64_t next_seed = 100;

  std::vector<double> Run(Environment& env, int steps) {
    std::vector<double> seen;
    std::vector<double> observation(env.spec().observation_size);
    for (int t = 0; t < steps; ++t) {
      absl::StatusOr<StepResult> result = env.Step(
          RandomAction(env.spec(), actions), absl::MakeSpan(observation));
      EXPECT_TRUE(result.ok()) << result.status();
      if (!result.ok()) break;
      seen.insert(seen.end(), observation.begin(), observation.end());
      seen.push_back(result->reward);
      seen.push_back(result->terminated);
      seen.push_back(result->truncated);
      if (result->terminated || result->truncated) {
        EXPECT_TRUE(env.Reset(next_seed++, absl::MakeSpan(observation)).ok());
        seen.insert(seen.end(), observation.begin(), observation.end());
      }
    }
    return seen;
  }
};

TEST(BulletEnvTest, SpecsAndObservationsAgree) {
  struct Expected {
    const char* name;
    int64_t observation;
    int64_t action;
    double control_dt;
  };
  for (const Expected& expected : {Expected{"BipedWalkFlat", 29, 11, 0.02},
                                   Expected{"BipedWalkIncline", 29, 11, 0.02},
                                   Expected{"BulletHopper", 11, 3, 0.008}}) {
    const auto env = Make(expected.name);
    ASSERT_NE(env, nullptr);
    const EnvSpec& spec = env->spec();
    EXPECT_EQ(spec.name, expected.name);
    EXPECT_EQ(spec.observation_size, expected.observation);
    EXPECT_FALSE(spec.discrete);
    EXPECT_EQ(spec.action_size, expected.action);
    EXPECT_EQ(spec.action_low, std::vector<double>(expected.action, -1.0));
    EXPECT_EQ(spec.action_high, std::vector<double>(expected.action, 1.0));
    EXPECT_DOUBLE_EQ(spec.control_dt, expected.control_dt);
    EXPECT_EQ(spec.max_episode_steps, 1000);

    std::vector<double> observation(spec.observation_size,
                                    std::numeric_limits<double>::quiet_NaN());
    ASSERT_TRUE(env->Reset(1, absl::MakeSpan(observation)).ok());
    for (double value : observation) EXPECT_TRUE(std::isfinite(value));
    std::vector<double> short_buffer(spec.observation_size - 1);
    EXPECT_EQ(env->Reset(1, absl::MakeSpan(short_buffer)).code(),
              absl::StatusCode::kInvalidArgument);
    ASSERT_TRUE(env->Reset(1, absl::MakeSpan(observation)).ok());
    std::mt19937_64 rng(1);
    EXPECT_EQ(env->Step(RandomAction(spec, rng), absl::MakeSpan(short_buffer))
                  .status()
                  .code(),
              absl::StatusCode::kInvalidArgument);
  }
}

TEST(BulletEnvTest, SameSeedAndActionsAreBitIdenticalOtherSeedsDiffer) {
  for (const char* name : kBulletEnvs) {
    const auto a = Make(name);
    const auto b = Make(name);
    std::vector<double> oa(a->spec().observation_size);
    std::vector<double> ob(oa.size());
    ASSERT_TRUE(a->Reset(7, absl::MakeSpan(oa)).ok());
    ASSERT_TRUE(b->Reset(7, absl::MakeSpan(ob)).ok());
    EXPECT_TRUE(BitEqual(oa, ob)) << name;
    Driver da, db;
    const std::vector<double> first = da.Run(*a, 300);
    EXPECT_TRUE(BitEqual(first, db.Run(*b, 300))) << name;

    // Again in an environment that has run other episodes since.
    ASSERT_TRUE(b->Reset(7, absl::MakeSpan(ob)).ok());
    EXPECT_TRUE(BitEqual(oa, ob)) << name;
    Driver again;
    EXPECT_TRUE(BitEqual(first, again.Run(*b, 300))) << name;

    ASSERT_TRUE(b->Reset(8, absl::MakeSpan(ob)).ok());
    EXPECT_FALSE(BitEqual(oa, ob)) << name;
  }
}

TEST(BulletEnvTest, OutOfBoundActionsAreClipped) {
  for (const char* name : kBulletEnvs) {
    const auto clipped = Make(name);
    const auto bounded = Make(name);
    const int64_t n = clipped->spec().action_size;
    std::vector<double> a(clipped->spec().observation_size), b(a.size());
    ASSERT_TRUE(clipped->Reset(2, absl::MakeSpan(a)).ok());
    ASSERT_TRUE(bounded->Reset(2, absl::MakeSpan(b)).ok());
    std::vector<double> huge(n), edge(n);
    for (int64_t i = 0; i < n; ++i) {
      huge[i] = (i % 3 == 0) ? 1e9 : (i % 3 == 1 ? -7.0 : 0.25);
      edge[i] = (i % 3 == 0) ? 1.0 : (i % 3 == 1 ? -1.0 : 0.25);
    }
    for (int t = 0; t < 5; ++t) {
      absl::StatusOr<StepResult> x = clipped->Step(huge, absl::MakeSpan(a));
      absl::StatusOr<StepResult> y = bounded->Step(edge, absl::MakeSpan(b));
      ASSERT_TRUE(x.ok() && y.ok()) << name;
      EXPECT_TRUE(BitEqual(a, b)) << name;
      // The effort term uses the clipped action.
      EXPECT_EQ(x->reward, y->reward) << name;
      if (x->terminated) break;
    }
  }
}

TEST(BulletEnvTest, NonFiniteOrMissizedActionsAreRefusedAndTheEpisodeGoesOn) {
  for (const char* name : kBulletEnvs) {
    const auto env = Make(name);
    const auto twin = Make(name);
    const int64_t n = env->spec().action_size;
    std::vector<double> observation(env->spec().observation_size);
    std::vector<double> expected(observation.size());
    ASSERT_TRUE(env->Reset(4, absl::MakeSpan(observation)).ok());
    ASSERT_TRUE(twin->Reset(4, absl::MakeSpan(expected)).ok());
    const std::vector<double> before = observation;
    std::vector<double> action(n, 0.1);
    for (const double bad :
         {std::nan(""), std::numeric_limits<double>::infinity()}) {
      action[1] = bad;
      absl::StatusOr<StepResult> refused =
          env->Step(action, absl::MakeSpan(observation));
      EXPECT_EQ(refused.status().code(), absl::StatusCode::kInvalidArgument);
      EXPECT_THAT(std::string(refused.status().message()),
                  HasSubstr("action[1] is not finite"));
      EXPECT_TRUE(BitEqual(observation, before)) << name;
    }
    action.pop_back();
    EXPECT_EQ(env->Step(action, absl::MakeSpan(observation)).status().code(),
              absl::StatusCode::kInvalidArgument);
    // Refused actions changed nothing: the next step is the twin's.
    const std::vector<double> fine(n, 0.1);
    ASSERT_TRUE(env->Step(fine, absl::MakeSpan(observation)).ok());
    ASSERT_TRUE(twin->Step(fine, absl::MakeSpan(expected)).ok());
    EXPECT_TRUE(BitEqual(observation, expected)) << name;
  }
}

TEST(BulletEnvTest, StepBeforeResetIsRefused) {
  absl::StatusOr<std::unique_ptr<Environment>> inner = MakeBipedWalkFlat();
  ASSERT_TRUE(inner.ok());
  std::vector<double> observation(29);
  EXPECT_EQ(
      (*inner)
          ->Step(std::vector<double>(11, 0.0), absl::MakeSpan(observation))
          .status()
          .code(),
      absl::StatusCode::kFailedPrecondition);
}

TEST(BulletEnvTest, RestoredEnvContinuesBitIdentically) {
  for (const char* name : kBulletEnvs) {
    const auto env = Make(name);
    std::vector<double> observation(env->spec().observation_size);
    ASSERT_TRUE(env->Reset(3, absl::MakeSpan(observation)).ok());
    Driver driver;
    driver.Run(*env, 37);  // mid-episode, after resets for the fragile ones
    absl::StatusOr<std::string> state = env->SaveState();
    ASSERT_TRUE(state.ok()) << state.status();
    const Driver at_save = driver;
    const std::vector<double> expected = driver.Run(*env, 150);

    for (const bool dirty : {false, true}) {
      const auto restored = Make(name);
      if (dirty) {
        ASSERT_TRUE(restored->Reset(99, absl::MakeSpan(observation)).ok());
        Driver other;
        other.actions.seed(42);
        other.Run(*restored, 25);
      }
      const absl::Status status = restored->RestoreState(*state);
      ASSERT_TRUE(status.ok()) << status;
      absl::StatusOr<std::string> again = restored->SaveState();
      ASSERT_TRUE(again.ok());
      EXPECT_EQ(*again, *state) << name;
      Driver replay = at_save;
      EXPECT_TRUE(BitEqual(expected, replay.Run(*restored, 150)))
          << name << (dirty ? " (dirty)" : " (fresh)");
    }
  }
}

TEST(BulletEnvTest, StateBeforeTheFirstResetNeedsAReset) {
  const auto fresh = Make("BipedWalkFlat");
  absl::StatusOr<std::string> state = fresh->SaveState();
  ASSERT_TRUE(state.ok());
  const auto used = Make("BipedWalkFlat");
  std::vector<double> observation(29);
  ASSERT_TRUE(used->Reset(1, absl::MakeSpan(observation)).ok());
  ASSERT_TRUE(used->RestoreState(*state).ok());
  EXPECT_EQ(
      used->Step(std::vector<double>(11, 0.0), absl::MakeSpan(observation))
          .status()
          .code(),
      absl::StatusCode::kFailedPrecondition);
}

// The inner environment's blob, as its fields.
struct InnerBlob {
  std::string name;
  uint64_t signature;
  bool needs_reset;
  uint64_t seed;
  std::vector<double> log, q, qd;

  static InnerBlob Parse(const std::string& blob) {
    StateReader reader(blob, "bullet_env", 1, "test");
    InnerBlob fields;
    fields.name = std::string(reader.GetBytes("name"));
    fields.signature = reader.GetU64("signature");
    fields.needs_reset = reader.GetBool("needs_reset");
    fields.seed = reader.GetU64("seed");
    for (std::vector<double>* out : {&fields.log, &fields.q, &fields.qd}) {
      const absl::string_view bytes = reader.GetBytes("doubles");
      out->resize(bytes.size() / sizeof(double));
      std::memcpy(out->data(), bytes.data(), bytes.size());
    }
    EXPECT_TRUE(reader.Finish().ok()) << reader.status();
    return fields;
  }

  std::string Write() const {
    StateWriter writer("bullet_env", 1);
    writer.PutBytes(name);
    writer.PutU64(signature);
    writer.PutBool(needs_reset);
    writer.PutU64(seed);
    writer.PutDoubles(log);
    writer.PutDoubles(q);
    writer.PutDoubles(qd);
    return std::move(writer).Finish();
  }
};

TEST(BulletEnvTest, BadStatesAreRefusedAndChangeNothing) {
  absl::StatusOr<std::unique_ptr<Environment>> made = MakeBipedWalkFlat();
  ASSERT_TRUE(made.ok());
  Environment& env = **made;
  std::vector<double> observation(29);
  ASSERT_TRUE(env.Reset(5, absl::MakeSpan(observation)).ok());
  const std::vector<double> zero(11, 0.0);
  for (int t = 0; t < 10; ++t) {
    ASSERT_TRUE(env.Step(zero, absl::MakeSpan(observation)).ok());
  }
  absl::StatusOr<std::string> good = env.SaveState();
  ASSERT_TRUE(good.ok());
  const InnerBlob fields = InnerBlob::Parse(*good);
  ASSERT_EQ(fields.log.size(), 110u);
  ASSERT_EQ(fields.q.size(), 14u);

  absl::StatusOr<std::unique_ptr<Environment>> hopper = MakeBulletHopper();
  ASSERT_TRUE(hopper.ok());
  std::vector<double> hopper_observation(11);
  ASSERT_TRUE((*hopper)->Reset(1, absl::MakeSpan(hopper_observation)).ok());

  std::vector<std::pair<std::string, std::string>> cases;
  cases.emplace_back(good->substr(0, good->size() - 9), "");
  cases.emplace_back("not a state", "");
  cases.emplace_back(*(*hopper)->SaveState(), "BulletHopper");
  InnerBlob other_task = fields;
  other_task.signature ^= 1;
  cases.emplace_back(other_task.Write(), "another model or rules");
  InnerBlob unclipped = fields;
  unclipped.log[13] = 1.5;
  cases.emplace_back(unclipped.Write(), "not a clipped action");
  InnerBlob ragged = fields;
  ragged.log.pop_back();
  cases.emplace_back(ragged.Write(), "impossible sizes");
  InnerBlob elsewhere = fields;
  elsewhere.q[1] += 1e-6;
  cases.emplace_back(elsewhere.Write(), "does not reproduce");
  InnerBlob other_seed = fields;
  ++other_seed.seed;
  cases.emplace_back(other_seed.Write(), "does not reproduce");

  for (const auto& [blob, message] : cases) {
    const absl::Status status = env.RestoreState(blob);
    EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument) << message;
    EXPECT_THAT(std::string(status.message()), HasSubstr(message));
    absl::StatusOr<std::string> now = env.SaveState();
    ASSERT_TRUE(now.ok());
    EXPECT_EQ(*now, *good) << message;
  }
  // The good blob still restores.
  EXPECT_TRUE(env.RestoreState(*good).ok());
}

// A pendulum with an infinite gear: Bullet clamps joint speeds (to 100), so
// large but finite torques cannot blow it up, but an infinite one turns the
// state into NaN, which is an error that asks for a reset; a reset
// recovers.
class ExplodingPendulum : public BulletEnv {
 public:
  ExplodingPendulum()
      : BulletEnv(Spec(), Model(), {std::numeric_limits<double>::infinity()},
                  5) {}

 private:
  static EnvSpec Spec() {
    EnvSpec spec;
    spec.name = "ExplodingPendulum";
    spec.observation_size = 2;
    return spec;
  }
  static PlanarModel Model() {
    PlanarModel model;
    model.root_z = 5.0;
    PlanarLink base;
    base.name = "base";
    base.from_x = -0.1;
    base.to_x = 0.1;
    base.from_z = base.to_z = 5.0;
    PlanarLink pole = base;
    pole.name = "pole";
    pole.parent = 0;
    pole.from_x = pole.to_x = 0.0;
    pole.from_z = 5.0;
    pole.to_z = 4.0;
    pole.joint_z = 5.0;
    pole.lower = -100.0;
    pole.upper = 100.0;
    model.links = {base, pole};
    return model;
  }
  void ResetState(std::mt19937_64&, std::vector<double>&,
                  std::vector<double>&) override {}
  StepResult Evaluate(const BulletWorld&, absl::Span<const double>) override {
    return {};
  }
  void Observe(const BulletWorld& world, double* observation) const override {
    observation[0] = world.q(3);
    observation[1] = world.qd(3);
  }
};

TEST(BulletEnvTest, NumericalBlowUpAsksForAReset) {
  ExplodingPendulum env;
  std::vector<double> observation(2);
  ASSERT_TRUE(env.Reset(0, absl::MakeSpan(observation)).ok());
  const absl::Status error =
      env.Step({1.0}, absl::MakeSpan(observation)).status();
  EXPECT_EQ(error.code(), absl::StatusCode::kInternal);
  EXPECT_THAT(std::string(error.message()), HasSubstr("reset the environment"));
  EXPECT_EQ(env.Step({0.0}, absl::MakeSpan(observation)).status().code(),
            absl::StatusCode::kFailedPrecondition);
  observation = {std::nan(""), std::nan("")};
  ASSERT_TRUE(env.Reset(0, absl::MakeSpan(observation)).ok());
  EXPECT_EQ(observation, std::vector<double>({0.0, 0.0}));
}

}  // namespace
}  // namespace vantage
