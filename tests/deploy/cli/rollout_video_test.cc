// `vantage rollout --video`: the real binary writes the file, Debian's
// ffprobe and ffmpeg read it back.

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/deploy/cli/run_vantage.h"
#include "tests/fakes/video_probe.h"

namespace vantage {
namespace {

using ::testing::HasSubstr;

std::string ResultLine(const std::string& out) {
  const size_t at = out.rfind("RESULT rollout");
  return at == std::string::npos ? "" : out.substr(at);
}

// One reset frame and one per step, summed over the first `episodes`
// episodes of the output (all if -1).
int64_t ExpectedFrames(const std::string& out, int episodes = -1) {
  int64_t frames = 0;
  int seen = 0;
  for (absl::string_view line : absl::StrSplit(out, '\n')) {
    const size_t at = line.find(" length=");
    if (!absl::StartsWith(line, "episode ") || at == absl::string_view::npos) {
      continue;
    }
    if (episodes >= 0 && seen == episodes) break;
    absl::string_view rest = line.substr(at + 8);
    int64_t length = 0;
    EXPECT_TRUE(absl::SimpleAtoi(rest.substr(0, rest.find(' ')), &length))
        << line;
    frames += length + 1;
    ++seen;
  }
  return frames;
}

// Frames at two times differ, and neither is a blank picture.
void ExpectMotion(const std::string& path, int64_t early, int64_t late,
                  size_t bytes) {
  const std::vector<uint8_t> a = DecodeFrame(path, early);
  const std::vector<uint8_t> b = DecodeFrame(path, late);
  ASSERT_EQ(a.size(), bytes);
  ASSERT_EQ(b.size(), bytes);
  EXPECT_FALSE(IsUniform(a));
  EXPECT_FALSE(IsUniform(b));
  EXPECT_NE(a, b);
}

TEST(RolloutVideoTest, HalfCheetahMp4HasAFrameAfterEveryResetAndStep) {
  const std::string path = TempPath("cheetah.mp4");
  // Two 1000-step episodes; a small frame keeps the test short.
  const Outcome outcome = RunVantage(absl::StrCat(
      "rollout --env=HalfCheetah --episodes=2 --seed=3 --video=", path,
      " --video_size=160x96"));
  ASSERT_EQ(outcome.exit_code, 0) << outcome.err;
  EXPECT_EQ(ExpectedFrames(outcome.out), 2002);
  EXPECT_THAT(outcome.out,
              HasSubstr(absl::StrCat("video: ", path,
                                     " (2002 frames, 160x96, 20 fps)")));
  const VideoProbe probe = ProbeVideo(path);
  ASSERT_TRUE(probe.ok) << path;
  EXPECT_EQ(probe.width, 160);
  EXPECT_EQ(probe.height, 96);
  EXPECT_EQ(probe.frames, 2002);
  ExpectMotion(path, 20, 400, 160 * 96 * 3);
}

TEST(RolloutVideoTest, BipedWalkFlatMp4AtTheControlFrequency) {
  const std::string path = TempPath("biped.mp4");
  const Outcome outcome = RunVantage(absl::StrCat(
      "rollout --env=BipedWalkFlat --episodes=2 --seed=1 --video=", path));
  ASSERT_EQ(outcome.exit_code, 0) << outcome.err;
  const int64_t frames = ExpectedFrames(outcome.out);
  ASSERT_GT(frames, 10);
  EXPECT_THAT(outcome.out,
              HasSubstr(absl::StrCat("video: ", path, " (", frames,
                                     " frames, 480x320, 50 fps)")));
  const VideoProbe probe = ProbeVideo(path);
  ASSERT_TRUE(probe.ok) << path;
  EXPECT_EQ(probe.width, 480);
  EXPECT_EQ(probe.height, 320);
  EXPECT_EQ(probe.frames, frames);
  ExpectMotion(path, 1, frames / 2, 480 * 320 * 3);
}

TEST(RolloutVideoTest, GifOfTheFirstEpisodesOnly) {
  const std::string path = TempPath("hopper.gif");
  // Hopper steps at 125 Hz: the GIF keeps every third frame (41.7 fps).
  const Outcome outcome = RunVantage(
      absl::StrCat("rollout --env=Hopper --episodes=3 --seed=2 --video=", path,
                   " --video_size=96x64 --video_episodes=2"));
  ASSERT_EQ(outcome.exit_code, 0) << outcome.err;
  const int64_t shown = ExpectedFrames(outcome.out, 2);
  const int64_t kept = (shown + 2) / 3;
  EXPECT_THAT(outcome.out,
              HasSubstr(absl::StrCat("video: ", path, " (", kept,
                                     " frames, 96x64, 41.6667 fps)")));
  const VideoProbe probe = ProbeVideo(path);
  ASSERT_TRUE(probe.ok) << path;
  EXPECT_EQ(probe.width, 96);
  EXPECT_EQ(probe.height, 64);
  EXPECT_EQ(probe.frames, kept);
  ExpectMotion(path, 0, kept - 1, 96 * 64 * 3);
}

TEST(RolloutVideoTest, TheRolloutIsTheSameWithAndWithoutAVideo) {
  const std::string args = "rollout --env=Hopper --episodes=3 --seed=5";
  const Outcome plain = RunVantage(args);
  const Outcome filmed = RunVantage(absl::StrCat(
      args, " --video=", TempPath("same.mp4"), " --video_size=64x48"));
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  ASSERT_EQ(filmed.exit_code, 0) << filmed.err;
  EXPECT_THAT(ResultLine(plain.out), HasSubstr("digest="));
  EXPECT_EQ(ResultLine(plain.out), ResultLine(filmed.out));
  EXPECT_THAT(filmed.out, HasSubstr("video: "));
  EXPECT_THAT(plain.out, ::testing::Not(HasSubstr("video: ")));
}

TEST(RolloutVideoTest, WhatCannotBeWrittenIsAUsageError) {
  Outcome outcome = RunVantage(
      absl::StrCat("rollout --env=BipedWalkFlat --episodes=1 --video=",
                   TempPath("clip.avi")));
  EXPECT_EQ(outcome.exit_code, 2);
  EXPECT_THAT(outcome.err, HasSubstr("unknown extension (use .mp4 or .gif)"));
  outcome = RunVantage(
      "rollout --env=BipedWalkFlat --episodes=1 "
      "--video=/nonexistent/dir/clip.mp4");
  EXPECT_EQ(outcome.exit_code, 2);
  EXPECT_THAT(outcome.err,
              HasSubstr("'/nonexistent/dir/clip.mp4': cannot open it for "
                        "writing"));
  EXPECT_FALSE(std::filesystem::exists("/nonexistent/dir/clip.mp4"));
  outcome = RunVantage(absl::StrCat(
      "rollout --env=BipedWalkFlat --episodes=1 --video_size=481x320 "
      "--video=",
      TempPath("odd.mp4")));
  EXPECT_EQ(outcome.exit_code, 2);
  EXPECT_THAT(outcome.err, HasSubstr("must be even"));
  outcome = RunVantage(
      "rollout --env=BipedWalkFlat --episodes=1 --video_size=big "
      "--video=x.mp4");
  EXPECT_EQ(outcome.exit_code, 2);
  EXPECT_THAT(outcome.err, HasSubstr("expected WIDTHxHEIGHT"));
  outcome = RunVantage(
      "rollout --env=BipedWalkFlat --episodes=1 --video_episodes=-1 "
      "--video=x.mp4");
  EXPECT_EQ(outcome.exit_code, 2);
  EXPECT_THAT(outcome.err, HasSubstr("--video_episodes must be >= 0"));
}

}  // namespace
}  // namespace vantage
