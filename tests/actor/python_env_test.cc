// Python environments through the embedded interpreter: the test tree's
// CartPole, Pendulum and image env (tests/python_envs, on PYTHONPATH with a
// stand-in gymnasium package), their specs, seeds, state and every error
// the bridge names.

#include "actor/envs/python/python_env.h"

#include <cmath>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "actor/envs/env_registry.h"
#include "actor/vector_env.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace vantage {
namespace {

using ::testing::HasSubstr;

std::unique_ptr<Environment> Make(const std::string& name,
                                  const std::string& kwargs = "") {
  EnvOptions options;
  options.python_kwargs = kwargs;
  absl::StatusOr<std::unique_ptr<Environment>> env =
      MakeEnvironment(name, options);
  EXPECT_TRUE(env.ok()) << env.status();
  return env.ok() ? *std::move(env) : nullptr;
}

std::string Error(const std::string& name, const std::string& kwargs = "") {
  EnvOptions options;
  options.python_kwargs = kwargs;
  absl::StatusOr<std::unique_ptr<Environment>> env =
      MakeEnvironment(name, options);
  if (!env.ok()) return std::string(env.status().message());
  std::vector<double> observation((*env)->spec().observation_size);
  if (absl::Status status = (*env)->Reset(1, absl::MakeSpan(observation));
      !status.ok()) {
    return std::string(status.message());
  }
  for (int i = 0; i < 3; ++i) {
    absl::StatusOr<StepResult> step =
        (*env)->Step({0.0}, absl::MakeSpan(observation));
    if (!step.ok()) return std::string(step.status().message());
  }
  return "";
}

TEST(PythonEnvTest, CartPoleDescribesItselfThroughItsSpaces) {
  for (const std::string& name :
       {std::string("python:cartpole:make"),
        std::string("python:tests/python_envs/cartpole.py:make"),
        std::string("gym:CartPole-v1")}) {
    std::unique_ptr<Environment> env = Make(name);
    ASSERT_NE(env, nullptr) << name;
    const EnvSpec& spec = env->spec();
    EXPECT_EQ(spec.name, name);
    EXPECT_EQ(spec.observation_size, 4);
    EXPECT_TRUE(spec.observation_shape.empty());
    EXPECT_FALSE(spec.byte_observations());
    EXPECT_TRUE(spec.discrete);
    EXPECT_EQ(spec.action_size, 2);
    EXPECT_EQ(spec.max_episode_steps, 500);
    EXPECT_DOUBLE_EQ(spec.control_dt, 1.0 / 50);
  }
}

// A pole left alone falls: terminated (not truncated) within 500 steps,
// reward 1 a step; with max_episode_steps=5 from the kwargs the env
// truncates first.
TEST(PythonEnvTest, StepsTerminatesAndTakesKwargs) {
  std::unique_ptr<Environment> env = Make("python:cartpole:make");
  ASSERT_NE(env, nullptr);
  std::vector<double> observation(4);
  ASSERT_TRUE(env->Reset(3, absl::MakeSpan(observation)).ok());
  for (double value : observation) EXPECT_LE(std::abs(value), 0.05);
  int steps = 0;
  StepResult last;
  while (steps < 500) {
    absl::StatusOr<StepResult> step =
        env->Step({1.0}, absl::MakeSpan(observation));
    ASSERT_TRUE(step.ok()) << step.status();
    EXPECT_EQ(step->reward, 1.0);
    ++steps;
    last = *step;
    if (step->terminated || step->truncated) break;
  }
  EXPECT_TRUE(last.terminated);
  EXPECT_LT(steps, 100);
  EXPECT_FALSE(env->Step({1.0}, absl::MakeSpan(observation)).ok());

  std::unique_ptr<Environment> short_env =
      Make("python:cartpole:make", R"({"max_episode_steps": 5})");
  ASSERT_NE(short_env, nullptr);
  EXPECT_EQ(short_env->spec().max_episode_steps, 5);
  ASSERT_TRUE(short_env->Reset(3, absl::MakeSpan(observation)).ok());
  for (int i = 0; i < 5; ++i) {
    absl::StatusOr<StepResult> step =
        short_env->Step({i % 2 == 0 ? 0.0 : 1.0}, absl::MakeSpan(observation));
    ASSERT_TRUE(step.ok()) << step.status();
    EXPECT_EQ(step->truncated, i == 4);
    EXPECT_FALSE(step->terminated);
  }
}

std::vector<double> Rollout(const std::string& name, uint64_t seed) {
  absl::StatusOr<std::unique_ptr<VectorEnv>> envs =
      VectorEnv::Create(name, 3, seed);
  EXPECT_TRUE(envs.ok()) << envs.status();
  if (!envs.ok()) return {};
  EXPECT_TRUE((*envs)->Reset().ok());
  std::vector<double> seen;
  const EnvSpec& spec = (*envs)->spec();
  for (int t = 0; t < 300; ++t) {
    std::vector<double> actions;
    for (int i = 0; i < 3; ++i) {
      if (spec.discrete) {
        actions.push_back((t + i) % static_cast<int>(spec.action_size));
      } else {
        actions.push_back(std::sin(0.1 * t + i));
      }
    }
    EXPECT_TRUE((*envs)->Step(actions).ok());
    seen.insert(seen.end(), (*envs)->observations().begin(),
                (*envs)->observations().end());
  }
  return seen;
}

TEST(PythonEnvTest, TheSameSeedGivesTheSameEpisodes) {
  for (const std::string& name :
       {std::string("python:cartpole:make"), std::string("gym:Pendulum-v1"),
        std::string("python:image_env:make")}) {
    const std::vector<double> first = Rollout(name, 11);
    EXPECT_EQ(first, Rollout(name, 11)) << name;
    EXPECT_NE(first, Rollout(name, 12)) << name;
  }
}

TEST(PythonEnvTest, ABoxActionIsClippedToItsBounds) {
  std::unique_ptr<Environment> env = Make("python:pendulum:make");
  ASSERT_NE(env, nullptr);
  const EnvSpec& spec = env->spec();
  EXPECT_FALSE(spec.discrete);
  EXPECT_EQ(spec.action_size, 1);
  EXPECT_EQ(spec.action_low, std::vector<double>{-2.0});
  EXPECT_EQ(spec.action_high, std::vector<double>{2.0});
  EXPECT_EQ(spec.max_episode_steps, 200);
  std::vector<double> a(3), b(3);
  std::unique_ptr<Environment> other = Make("python:pendulum:make");
  ASSERT_TRUE(env->Reset(5, absl::MakeSpan(a)).ok());
  ASSERT_TRUE(other->Reset(5, absl::MakeSpan(b)).ok());
  absl::StatusOr<StepResult> far = env->Step({50.0}, absl::MakeSpan(a));
  absl::StatusOr<StepResult> bound = other->Step({2.0}, absl::MakeSpan(b));
  ASSERT_TRUE(far.ok() && bound.ok());
  EXPECT_EQ(a, b);
  EXPECT_EQ(far->reward, bound->reward);
}

// Gymnasium's images are height x width x channels; vantage's are
// channels first, and travel as bytes.
TEST(PythonEnvTest, ImagesAreBytesChannelsFirst) {
  std::unique_ptr<Environment> env = Make("python:image_env:make");
  ASSERT_NE(env, nullptr);
  const EnvSpec& spec = env->spec();
  EXPECT_EQ(spec.observation_shape, (std::vector<int64_t>{3, 10, 10}));
  EXPECT_EQ(spec.observation_size, 300);
  EXPECT_EQ(spec.observation_high, 255);
  std::vector<double> observation(300);
  ASSERT_TRUE(env->Reset(1, absl::MakeSpan(observation)).ok());
  // The green corner: channel 1, row 9, column 9.
  EXPECT_EQ(observation[(1 * 10 + 9) * 10 + 9], 255.0);
  double red = 0;
  for (int i = 0; i < 100; ++i) red += observation[i];
  EXPECT_EQ(red, 255.0);  // one red dot
}

TEST(PythonEnvTest, ACartPoleStateRestoresExactly) {
  std::unique_ptr<Environment> env = Make("python:cartpole:make");
  ASSERT_NE(env, nullptr);
  std::vector<double> observation(4);
  ASSERT_TRUE(env->Reset(9, absl::MakeSpan(observation)).ok());
  ASSERT_TRUE(env->Step({1.0}, absl::MakeSpan(observation)).ok());
  absl::StatusOr<std::string> state = env->SaveState();
  ASSERT_TRUE(state.ok()) << state.status();
  std::vector<double> first, second;
  for (int i = 0; i < 5; ++i) {
    ASSERT_TRUE(env->Step({0.0}, absl::MakeSpan(observation)).ok());
    first.insert(first.end(), observation.begin(), observation.end());
  }
  std::unique_ptr<Environment> restored = Make("python:cartpole:make");
  ASSERT_TRUE(restored->RestoreState(*state).ok());
  for (int i = 0; i < 5; ++i) {
    ASSERT_TRUE(restored->Step({0.0}, absl::MakeSpan(observation)).ok());
    second.insert(second.end(), observation.begin(), observation.end());
  }
  EXPECT_EQ(first, second);
  EXPECT_FALSE(restored->RestoreState("not a state").ok());
  // Pendulum offers no get_state().
  std::unique_ptr<Environment> pendulum = Make("python:pendulum:make");
  EXPECT_EQ(pendulum->SaveState().status().code(),
            absl::StatusCode::kUnimplemented);
}

// In a checkpoint's actor state: CartPole (get_state) continues exactly;
// Pendulum (none) restarts its episodes and the state still restores.
TEST(PythonEnvTest, AVectorOfThemResumesExactlyOrRestartsItsEpisodes) {
  for (const std::string& name : {std::string("python:cartpole:make"),
                                  std::string("python:pendulum:make")}) {
    const bool exact = name == "python:cartpole:make";
    absl::StatusOr<std::unique_ptr<VectorEnv>> envs =
        VectorEnv::Create(name, 2, 4);
    ASSERT_TRUE(envs.ok()) << envs.status();
    ASSERT_TRUE((*envs)->Reset().ok());
    const std::vector<double> action(2, 0.0);
    for (int t = 0; t < 7; ++t) ASSERT_TRUE((*envs)->Step(action).ok());
    absl::StatusOr<std::string> state = (*envs)->SaveState();
    ASSERT_TRUE(state.ok()) << state.status();
    ASSERT_TRUE((*envs)->Step(action).ok());
    const std::vector<double> next((*envs)->observations().begin(),
                                   (*envs)->observations().end());
    absl::StatusOr<std::unique_ptr<VectorEnv>> resumed =
        VectorEnv::Create(name, 2, 4);
    ASSERT_TRUE(resumed.ok());
    ASSERT_TRUE((*resumed)->RestoreState(*state).ok()) << name;
    ASSERT_TRUE((*resumed)->Step(action).ok());
    const std::vector<double> resumed_next((*resumed)->observations().begin(),
                                           (*resumed)->observations().end());
    if (exact) {
      EXPECT_EQ(resumed_next, next);
    } else {
      EXPECT_NE(resumed_next, next);
    }
  }
}

EnvOptions Kwargs(const std::string& json) {
  EnvOptions options;
  options.python_kwargs = json;
  return options;
}

// Steps `envs` `steps` times pressing each env's first legal button (the
// test env raises on an unlit one); the first error, if any.
absl::Status PressLegalButtons(VectorEnv& envs, int steps) {
  const int64_t n = envs.spec().action_size;
  for (int t = 0; t < steps; ++t) {
    std::vector<double> actions;
    for (int e = 0; e < envs.size(); ++e) {
      const auto begin = envs.action_masks().begin() + e * n;
      actions.push_back(
          static_cast<double>(std::find(begin, begin + n, 1) - begin));
    }
    if (absl::Status status = envs.Step(actions); !status.ok()) return status;
  }
  return absl::OkStatus();
}

// Gymnasium's two places for a mask: info["action_mask"] of every reset
// and step, or an observation Dict of "observation" and "action_mask"; the
// mask is the lit buttons' and only legal presses are made. Without a
// mask the env is unmasked.
TEST(PythonEnvTest, MasksComeFromTheInfoOrAnObservationKey) {
  for (const std::string mask_in : {"info", "observation", "none"}) {
    absl::StatusOr<std::unique_ptr<VectorEnv>> made = VectorEnv::Create(
        "python:lit_buttons:make", 3, 4,
        Kwargs(absl::StrCat(R"({"mask_in": ")", mask_in, R"("})")));
    ASSERT_TRUE(made.ok()) << made.status();
    VectorEnv& envs = **made;
    EXPECT_EQ(envs.spec().observation_size, 16) << mask_in;
    if (mask_in == "none") {
      EXPECT_FALSE(envs.spec().action_masks);
      EXPECT_TRUE(envs.action_masks().empty());
      continue;
    }
    EXPECT_EQ(envs.spec().ActionString(), "discrete:8 masked");
    ASSERT_TRUE(envs.Reset().ok());
    for (int t = 0; t < 40; ++t) {
      for (int e = 0; e < 3; ++e) {
        for (int i = 0; i < 8; ++i) {
          ASSERT_EQ(envs.action_masks()[e * 8 + i],
                    envs.observations()[e * 16 + i])
              << mask_in;
        }
      }
      ASSERT_TRUE(PressLegalButtons(envs, 1).ok()) << mask_in;
    }
  }
}

// A mask of the wrong length, all zero, not boolean or missing is refused
// naming the env, the call and what is wrong.
TEST(PythonEnvTest, BadMasksAreRefusedByName) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"short",
       "the action mask has 7 entries, expected 8 (step()'s "
       "action_mask)"},
      {"zeros",
       "the action mask is all zero (no legal action) (step()'s "
       "action_mask)"},
      {"twos", "action mask entry "},
      {"floats",
       "step() gave an action_mask that is not a 1-D array of "
       "booleans"},
      {"missing",
       "step()'s info has no action_mask (the first reset's had "
       "one, so every reset and step must)"},
  };
  for (const auto& [bad, message] : cases) {
    const std::string mask_in = bad == "floats" ? "observation" : "info";
    absl::StatusOr<std::unique_ptr<VectorEnv>> made = VectorEnv::Create(
        "python:lit_buttons:make", 1, 4,
        Kwargs(absl::StrCat(R"({"mask_in": ")", mask_in, R"(", "bad_mask": ")",
                            bad, R"(", "bad_after": 3})")));
    ASSERT_TRUE(made.ok()) << made.status();
    ASSERT_TRUE((*made)->Reset().ok());
    const absl::Status status = PressLegalButtons(**made, 5);
    EXPECT_THAT(status.message(), HasSubstr(message)) << bad;
    EXPECT_THAT(status.message(), HasSubstr("python:lit_buttons:make")) << bad;
  }
}

// A masked env with get_state resumes exactly, its masks too.
TEST(PythonEnvTest, AMaskedEnvResumesWithItsMasks) {
  const auto make = [] {
    return *VectorEnv::Create("python:lit_buttons:make", 2, 4);
  };
  std::unique_ptr<VectorEnv> envs = make();
  ASSERT_TRUE(envs->Reset().ok());
  ASSERT_TRUE(PressLegalButtons(*envs, 5).ok());
  absl::StatusOr<std::string> state = envs->SaveState();
  ASSERT_TRUE(state.ok()) << state.status();
  std::unique_ptr<VectorEnv> resumed = make();
  ASSERT_TRUE(resumed->RestoreState(*state).ok());
  EXPECT_EQ(resumed->action_masks(), envs->action_masks());
  ASSERT_TRUE(PressLegalButtons(*envs, 3).ok());
  ASSERT_TRUE(PressLegalButtons(*resumed, 3).ok());
  EXPECT_EQ(std::vector<double>(resumed->observations().begin(),
                                resumed->observations().end()),
            std::vector<double>(envs->observations().begin(),
                                envs->observations().end()));
  EXPECT_EQ(resumed->action_masks(), envs->action_masks());
}

// A Dict (or Tuple) of a 5x5 camera image and a 2-value vector: entries
// side by side in the row, the image channels first, described in the
// spec for the networks.
TEST(PythonEnvTest, DictAndTupleObservationsAreEntriesSideBySide) {
  for (const std::string kwargs : {"", R"({"tuple": 1})"}) {
    std::unique_ptr<Environment> env = Make("python:lit_pixel:make", kwargs);
    const EnvSpec& spec = env->spec();
    const std::string camera = kwargs.empty() ? "camera" : "0";
    const std::string mirror = kwargs.empty() ? "mirror" : "1";
    EXPECT_EQ(spec.ObservationString(),
              absl::StrCat("dict(", camera, ": uint8 1x5x5, ", mirror, ": 2)"));
    ASSERT_TRUE(CheckObservationLayout(spec).ok());
    ASSERT_EQ(spec.observation_size, 27);
    EXPECT_EQ(spec.observation_keys[0].high, 255);
    std::vector<double> observation(27);
    ASSERT_TRUE(env->Reset(3, absl::MakeSpan(observation)).ok());
    for (int step = 0; step < 3; ++step) {
      int lit = 0;
      for (int i = 0; i < 25; ++i) lit += observation[i] == 255.0;
      EXPECT_EQ(lit, 1);
      EXPECT_EQ(observation[25] + observation[26], 1.0);
      ASSERT_TRUE(env->Step({0.0}, absl::MakeSpan(observation)).ok());
    }
  }
}

TEST(PythonEnvTest, RendersAnRgbFrameOfTheAskedSize) {
  std::unique_ptr<Environment> env = Make("python:cartpole:make");
  std::vector<double> observation(4);
  ASSERT_TRUE(env->Reset(1, absl::MakeSpan(observation)).ok());
  absl::StatusOr<Frame> frame = env->Render(64, 32);
  ASSERT_TRUE(frame.ok()) << frame.status();
  EXPECT_EQ(frame->width, 64);
  EXPECT_EQ(frame->height, 32);
  EXPECT_EQ(frame->rgb.size(), 64u * 32 * 3);
  EXPECT_EQ(Make("python:pendulum:make")->Render(8, 8).status().code(),
            absl::StatusCode::kUnimplemented);
}

TEST(PythonEnvTest, EveryErrorNamesTheEnvTheCallAndTheCause) {
  EXPECT_THAT(Error("python:no_such_module:make"),
              HasSubstr("python:no_such_module:make: the factory: "
                        "ModuleNotFoundError: No module named "
                        "'no_such_module'"));
  EXPECT_THAT(Error("python:cartpole:no_such_factory"),
              HasSubstr("AttributeError"));
  EXPECT_THAT(Error("python:broken_envs:not_callable"),
              HasSubstr("is not callable"));
  EXPECT_THAT(Error("python:broken_envs:raises_in_factory"),
              HasSubstr("the factory: RuntimeError: no simulator licence "
                        "(broken_envs.py:"));
  EXPECT_THAT(Error("python:broken_envs:raises_in_step"),
              HasSubstr("python:broken_envs:raises_in_step: step(): "
                        "ValueError: the simulator crashed on 0 "
                        "(broken_envs.py:"));
  EXPECT_THAT(Error("python:broken_envs:raises_in_step"),
              HasSubstr("in fail)"));
  EXPECT_THAT(Error("python:broken_envs:wrong_shape"),
              HasSubstr("reset() returned an observation of shape (3,); the "
                        "observation space's is (4,)"));
  EXPECT_THAT(Error("python:broken_envs:wrong_dtype"),
              HasSubstr("reset() returned an observation of dtype int64"));
  EXPECT_THAT(Error("python:broken_envs:nan_observation"),
              HasSubstr("step() returned an observation whose value 1 is nan"));
  EXPECT_THAT(Error("python:broken_envs:infinite_reward"),
              HasSubstr("step() returned the reward inf, which is not finite"));
  EXPECT_THAT(Error("python:broken_envs:old_gym_api"),
              HasSubstr("step() must return (observation, reward, terminated, "
                        "truncated, info) as Gymnasium does; it returned a "
                        "tuple of 4"));
  EXPECT_THAT(Error("python:broken_envs:dict_observations"),
              HasSubstr("reset() returned an observation without its dict "
                        "entry 'a', which its space has"));
  EXPECT_THAT(Error("python:broken_envs:nested_dict"),
              HasSubstr("its spaces: TypeError: observation['a'] is a Dict "
                        "space inside the Dict space; vantage takes one level "
                        "of Dict or Tuple"));
  EXPECT_THAT(Error("python:broken_envs:text_entry"),
              HasSubstr("TypeError: the observation['note'] space is a Text "
                        "space; vantage takes a box"));
  EXPECT_THAT(Error("python:cartpole"), HasSubstr("names no factory"));
  EXPECT_THAT(Error("gym:"), HasSubstr("gym: needs an id"));
  EXPECT_THAT(Error("python:cartpole:make", "[1, 2]"),
              HasSubstr("--env_kwargs must be a JSON object"));
  EXPECT_THAT(Error("python:cartpole:make", R"({"no_such": 1})"),
              HasSubstr("TypeError"));
  EXPECT_THAT(Error("Hopper", R"({"a": 1})"),
              HasSubstr("--env_kwargs is for Python environments"));
  // An action outside n never reaches Python.
  std::unique_ptr<Environment> env = Make("python:cartpole:make");
  std::vector<double> observation(4);
  ASSERT_TRUE(env->Reset(1, absl::MakeSpan(observation)).ok());
  EXPECT_THAT(
      std::string(
          env->Step({2.0}, absl::MakeSpan(observation)).status().message()),
      HasSubstr("discrete action 2 is not an integer in [0, 2)"));
}

TEST(PythonEnvTest, APlainPythonLoopIsTimedForTheBench) {
  absl::StatusOr<double> rate =
      PlainPythonStepsPerSecond("python:cartpole:make", "", {1.0}, 2000);
  ASSERT_TRUE(rate.ok()) << rate.status();
  EXPECT_GT(*rate, 0.0);
}

}  // namespace
}  // namespace vantage
