#include "deploy/cli/env_commands.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <optional>
#include <random>
#include <vector>

#include "absl/flags/flag.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_replace.h"
#include "absl/strings/str_split.h"
#include "actor/envs/env_registry.h"
#include "deploy/cli/command_line.h"
#include "deploy/cli/shared_flags.h"
#include "deploy/observe/video_writer.h"
#include "deploy/run/run_config.h"
#include "deploy/run/trained_policy.h"

ABSL_FLAG(int64_t, episodes, 10, "number of episodes");
ABSL_FLAG(bool, stochastic, false,
          "with --checkpoint: sample actions instead of the mean / mode");
ABSL_FLAG(std::string, video, "",
          "write the episodes to this video file: .mp4 (H.264) or .gif, "
          "one frame after each reset and each step");
ABSL_FLAG(std::string, video_size, "480x320",
          "with --video: WIDTHxHEIGHT in pixels, both even");
ABSL_FLAG(int64_t, video_episodes, 0,
          "with --video: how many of the first episodes it shows (0: all)");

namespace vantage {
namespace {

struct RolloutRequest {
  std::string env;  // may be empty with a checkpoint (the run's env)
  int64_t episodes = 10;
  uint64_t seed = 0;
  std::string checkpoint;   // run directory or checkpoint file
  bool stochastic = false;  // sample instead of the mean / mode
  std::string video;        // empty: no video
  int video_width = 480;
  int video_height = 320;
  int64_t video_episodes = 0;  // 0: all
};

absl::Status ParseVideoSize(const std::string& text, RolloutRequest* request) {
  const std::vector<std::string> parts = absl::StrSplit(text, 'x');
  if (parts.size() != 2 || !absl::SimpleAtoi(parts[0], &request->video_width) ||
      !absl::SimpleAtoi(parts[1], &request->video_height)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "--video_size=", text, ": expected WIDTHxHEIGHT, e.g. 480x320"));
  }
  return absl::OkStatus();
}

// The frames of a rollout's first episodes, into a file opened at the first
// frame (once the environment has shown it can render).
class VideoRecorder {
 public:
  VideoRecorder(const RolloutRequest& request, const EnvSpec& spec)
      : request_(request), spec_(spec) {}

  bool recording(int64_t episode) const {
    return !request_.video.empty() &&
           (request_.video_episodes == 0 || episode < request_.video_episodes);
  }

  // Renders `env` as it stands; `code` says how the command should end
  // when it fails.
  absl::Status Add(Environment& env, int* code) {
    absl::StatusOr<Frame> frame =
        env.Render(request_.video_width, request_.video_height);
    if (!frame.ok()) {
      *code =
          absl::IsUnimplemented(frame.status()) ? kUsageError : kRuntimeError;
      return absl::Status(
          frame.status().code(),
          absl::StrCat(spec_.name, " cannot render a video frame: ",
                       frame.status().message()));
    }
    if (writer_ == nullptr) {
      absl::StatusOr<std::unique_ptr<VideoWriter>> opened =
          VideoWriter::Open(request_.video, request_.video_width,
                            request_.video_height, 1.0 / spec_.control_dt);
      if (!opened.ok()) {
        *code = kUsageError;
        return opened.status();
      }
      writer_ = *std::move(opened);
    }
    *code = kRuntimeError;
    return writer_->Write(*frame);
  }

  absl::Status Finish() {
    if (writer_ == nullptr) return absl::OkStatus();
    if (absl::Status status = writer_->Finish(); !status.ok()) return status;
    std::printf("video: %s (%ld frames, %dx%d, %g fps)\n",
                request_.video.c_str(),
                static_cast<long>(writer_->frames_written()),
                request_.video_width, request_.video_height, writer_->fps());
    return absl::OkStatus();
  }

 private:
  const RolloutRequest& request_;
  const EnvSpec& spec_;
  std::unique_ptr<VideoWriter> writer_;
};

// `code`: kUsageError for what the flags asked for, kRuntimeError for a
// failure while running.
int Fail(const char* command, const absl::Status& status,
         int code = kUsageError) {
  return CommandFailure(command, code, std::string(status.message()));
}

// FNV-1a over the observations' bytes: cheap, and any change shows.
class Digest {
 public:
  void Add(const std::vector<double>& values) {
    const auto* bytes = reinterpret_cast<const unsigned char*>(values.data());
    for (size_t i = 0; i < values.size() * sizeof(double); ++i) {
      hash_ = (hash_ ^ bytes[i]) * 0x100000001b3ULL;
    }
  }
  uint64_t value() const { return hash_; }

 private:
  uint64_t hash_ = 0xcbf29ce484222325ULL;
};

int RunEnvs(const std::vector<std::string>&) {
  for (const std::string& name : RegisteredEnvironments()) {
    absl::StatusOr<std::unique_ptr<Environment>> env = MakeEnvironment(name);
    if (!env.ok()) return Fail("envs", env.status(), kRuntimeError);
    const EnvSpec& spec = (*env)->spec();
    std::printf("%s obs=[%s] act=%s\n", name.c_str(),
                spec.ObservationString().c_str(), spec.ActionString().c_str());
    for (const EnvOptionInfo& option : EnvironmentOptions(name)) {
      std::printf("  :%s=%s  %s\n", option.name.c_str(),
                  option.default_value.c_str(), option.help.c_str());
    }
  }
  return 0;
}

namespace {

absl::StatusOr<RolloutRequest> RolloutRequestFromFlags() {
  RolloutRequest request;
  request.env = absl::GetFlag(FLAGS_env);
  request.episodes = absl::GetFlag(FLAGS_episodes);
  request.seed = absl::GetFlag(FLAGS_seed);
  request.checkpoint = absl::GetFlag(FLAGS_checkpoint);
  request.stochastic = absl::GetFlag(FLAGS_stochastic);
  request.video = absl::GetFlag(FLAGS_video);
  request.video_episodes = absl::GetFlag(FLAGS_video_episodes);
  if (absl::Status status =
          ParseVideoSize(absl::GetFlag(FLAGS_video_size), &request);
      !status.ok()) {
    return status;
  }
  if (request.video_episodes < 0) {
    return absl::InvalidArgumentError("--video_episodes must be >= 0 (0: all)");
  }
  return request;
}

// The policy of --checkpoint, if one is given; its run's env becomes
// request.env when that is empty and must equal it otherwise.
absl::StatusOr<std::optional<TrainedPolicy>> LoadRolloutPolicy(
    RolloutRequest& request) {
  if (request.checkpoint.empty()) return std::optional<TrainedPolicy>();
  absl::StatusOr<TrainedPolicy> trained = LoadTrainedPolicy(request.checkpoint);
  if (!trained.ok()) return trained.status();
  const std::string& trained_env = trained->config.training().env();
  if (request.env.empty()) request.env = trained_env;
  if (request.env != trained_env) {
    return absl::InvalidArgumentError(
        absl::StrCat("the checkpoint's policy was trained on ", trained_env,
                     ", not ", request.env));
  }
  std::printf("policy: %s (version %ld, %s actions)\n",
              trained->checkpoint_path.c_str(),
              static_cast<long>(trained->version),
              request.stochastic ? "sampled" : "deterministic");
  trained->Seed(request.seed);
  return std::optional<TrainedPolicy>(*std::move(trained));
}

// The rollout's actions: the trained policy's, or uniform random ones.
class RolloutActions {
 public:
  RolloutActions(const EnvSpec& spec, std::optional<TrainedPolicy>& trained,
                 const RolloutRequest& request)
      : spec_(spec),
        trained_(trained),
        deterministic_(!request.stochastic),
        rng_(request.seed),
        action_(spec.action_width()) {}

  void StartEpisode() {
    if (trained_.has_value()) trained_->StartEpisode();
  }

  // `mask`: the legal actions (ReadActionMask's; empty: all are).
  const std::vector<double>& Act(const std::vector<double>& observation,
                                 const std::vector<uint8_t>& mask) {
    if (trained_.has_value()) {
      action_ = trained_->Act(observation, deterministic_, mask);
    } else if (spec_.discrete) {
      // Uniform over each head's legal choices.
      const std::vector<int64_t> heads = spec_.action_heads();
      int64_t offset = 0;
      for (size_t h = 0; h < heads.size(); offset += heads[h], ++h) {
        std::vector<int64_t> legal;
        for (int64_t i = 0; i < heads[h]; ++i) {
          if (mask.empty() || mask[offset + i]) legal.push_back(i);
        }
        action_[h] =
            static_cast<double>(legal[std::uniform_int_distribution<size_t>(
                0, legal.size() - 1)(rng_)]);
      }
    } else {
      for (size_t i = 0; i < action_.size(); ++i) {
        // Unbounded actuators get actions in [-1, 1].
        const double low =
            std::isfinite(spec_.action_low[i]) ? spec_.action_low[i] : -1.0;
        const double high =
            std::isfinite(spec_.action_high[i]) ? spec_.action_high[i] : 1.0;
        action_[i] = std::uniform_real_distribution<double>(low, high)(rng_);
      }
    }
    return action_;
  }

 private:
  const EnvSpec& spec_;
  std::optional<TrainedPolicy>& trained_;
  const bool deterministic_;
  std::mt19937_64 rng_;
  std::vector<double> action_;
};

struct RolloutTotals {
  double total_return = 0.0;
  int64_t total_length = 0;
  Digest digest;
};

// Plays episode `episode` (recorded if the video wants it) into `totals`;
// 0, or the exit code of the failure it reported.
int PlayEpisode(Environment& env, int64_t episode, uint64_t seed,
                RolloutActions& actions, VideoRecorder& video,
                RolloutTotals& totals) {
  std::vector<double> observation(env.spec().observation_size);
  if (absl::Status status =
          env.Reset(seed * 1000003 + episode, absl::MakeSpan(observation));
      !status.ok()) {
    return Fail("rollout", status, kRuntimeError);
  }
  totals.digest.Add(observation);
  actions.StartEpisode();
  // A frame after the reset and after every step.
  const bool recording = video.recording(episode);
  int video_code = kRuntimeError;
  absl::Status recorded =
      recording ? video.Add(env, &video_code) : absl::OkStatus();
  double episode_return = 0.0;
  int64_t length = 0;
  while (recorded.ok()) {
    absl::StatusOr<std::vector<uint8_t>> mask = ReadActionMask(env);
    if (!mask.ok()) return Fail("rollout", mask.status(), kRuntimeError);
    absl::StatusOr<StepResult> result =
        env.Step(actions.Act(observation, *mask), absl::MakeSpan(observation));
    if (!result.ok()) return Fail("rollout", result.status(), kRuntimeError);
    totals.digest.Add(observation);
    if (recording) recorded = video.Add(env, &video_code);
    if (!recorded.ok()) break;
    episode_return += result->reward;
    ++length;
    if (result->terminated || result->truncated) {
      std::printf("episode %ld return=%.3f length=%ld %s\n",
                  static_cast<long>(episode), episode_return,
                  static_cast<long>(length),
                  result->terminated ? "terminated" : "truncated");
      break;
    }
  }
  if (!recorded.ok()) return Fail("rollout", recorded, video_code);
  totals.total_return += episode_return;
  totals.total_length += length;
  return 0;
}

}  // namespace

int RunRollout(const std::vector<std::string>&) {
  absl::StatusOr<RolloutRequest> request = RolloutRequestFromFlags();
  if (!request.ok()) return Fail("rollout", request.status());
  absl::StatusOr<std::optional<TrainedPolicy>> trained =
      LoadRolloutPolicy(*request);
  if (!trained.ok()) return Fail("rollout", trained.status());
  if (request->env.empty()) {
    return Fail("rollout", absl::InvalidArgumentError(
                               "--env=NAME is required (see `vantage envs`)"));
  }
  const int64_t episodes = request->episodes;
  if (episodes < 1) {
    return Fail("rollout",
                absl::InvalidArgumentError("--episodes must be >= 1"));
  }
  // A trained policy sees the environment as its run wrapped it (and made
  // it, for a Python env, unless --env_kwargs says otherwise).
  EnvOptions options =
      trained->has_value() ? EnvOptionsOf((*trained)->config) : EnvOptions{};
  if (FlagGiven("env_kwargs")) {
    options.python_kwargs = absl::GetFlag(FLAGS_env_kwargs);
  }
  absl::StatusOr<std::unique_ptr<Environment>> made =
      MakeEnvironment(request->env, options);
  if (!made.ok()) return Fail("rollout", made.status());
  Environment& env = **made;
  const EnvSpec& spec = env.spec();
  RolloutActions actions(spec, *trained, *request);
  VideoRecorder video(*request, spec);
  RolloutTotals totals;
  for (int64_t episode = 0; episode < episodes; ++episode) {
    if (const int code =
            PlayEpisode(env, episode, request->seed, actions, video, totals);
        code != 0) {
      return code;
    }
  }
  if (absl::Status status = video.Finish(); !status.ok()) {
    return Fail("rollout", status, kRuntimeError);
  }
  std::printf(
      "RESULT rollout env=%s obs_dim=%ld act_dim=%ld episodes=%ld "
      "mean_return=%.3f mean_length=%.1f digest=%016lx\n",
      request->env.c_str(), static_cast<long>(spec.observation_size),
      static_cast<long>(spec.action_size), static_cast<long>(episodes),
      totals.total_return / episodes,
      static_cast<double>(totals.total_length) / episodes,
      static_cast<unsigned long>(totals.digest.value()));
  return 0;
}

}  // namespace

Command EnvsCommand() {
  Command command;
  command.name = "envs";
  command.summary = "list the registered environments";
  command.usage = "vantage envs";
  command.description =
      "One line per registered environment: its name, observation shape and\n"
      "action space, then the options it takes (`  :name=default  help`).\n"
      "Any of them (or mjcf:PATH) is a valid --env, and so is a name with\n"
      "options: --env=HalfCheetah:ctrl_cost=0.2,max_episode_steps=500.";
  command.example = "vantage envs";
  command.run = RunEnvs;
  return command;
}

Command RolloutCommand() {
  Command command;
  command.name = "rollout";
  command.summary = "episodes of a random or a trained policy";
  command.usage = "vantage rollout (--env=NAME | --checkpoint=RUN) [flags]";
  command.description =
      "Runs --episodes episodes with a uniform-random policy, or with\n"
      "--checkpoint the policy of a run directory's newest checkpoint (its\n"
      "mean action unless --stochastic), one line per episode, then\n"
      "`RESULT rollout ... mean_return=R mean_length=L digest=D` (the digest\n"
      "hashes every observation: equal digests, equal episodes).\n"
      "--video=FILE renders the episodes offscreen (MuJoCo's renderer on\n"
      "OSMesa; the Bullet characters side-on with Cairo) into an MP4 or GIF\n"
      "at the control frequency, one frame after each reset and each step,\n"
      "and prints `video: FILE (N frames, WxH, F fps)`; the episodes and\n"
      "the RESULT line are the same with or without it (docs/videos.md).";
  command.flags = {"env",   "env_kwargs", "episodes",
                   "seed",  "checkpoint", "stochastic",
                   "video", "video_size", "video_episodes"};
  command.defaults = {{"env", "the checkpoint's, else required"}};
  command.example =
      "vantage rollout --checkpoint=runs/hopper --episodes=5 "
      "--video=hopper.mp4";
  command.run = RunRollout;
  return command;
}

}  // namespace vantage
