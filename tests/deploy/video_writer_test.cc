#include "deploy/observe/video_writer.h"

#include <filesystem>
#include <string>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/fakes/video_probe.h"

namespace vantage {
namespace {

using ::testing::HasSubstr;

std::string OutputPath(const std::string& name) {
  return ::testing::TempDir() + "/video_writer_test_" + name;
}

// A bright square that moves right by `step` pixels per frame over a
// gradient.
Frame MovingSquare(int width, int height, int step) {
  Frame frame;
  frame.width = width;
  frame.height = height;
  frame.rgb.resize(3 * width * height);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      uint8_t* pixel = frame.rgb.data() + 3 * (y * width + x);
      const bool square =
          x >= 4 * step && x < 4 * step + 16 && y >= 8 && y < 24;
      pixel[0] = square ? 250 : static_cast<uint8_t>(x);
      pixel[1] = square ? 240 : static_cast<uint8_t>(y);
      pixel[2] = square ? 20 : 128;
    }
  }
  return frame;
}

TEST(VideoWriterTest, Mp4HoldsEveryFrameAtItsSize) {
  const std::string path = OutputPath("square.mp4");
  auto writer = VideoWriter::Open(path, 64, 48, 20.0);
  ASSERT_TRUE(writer.ok()) << writer.status();
  for (int i = 0; i < 10; ++i) {
    ASSERT_TRUE((*writer)->Write(MovingSquare(64, 48, i)).ok());
  }
  ASSERT_TRUE((*writer)->Finish().ok());
  EXPECT_EQ((*writer)->frames_written(), 10);
  EXPECT_EQ((*writer)->fps(), 20.0);
  const VideoProbe probe = ProbeVideo(path);
  ASSERT_TRUE(probe.ok);
  EXPECT_EQ(probe.width, 64);
  EXPECT_EQ(probe.height, 48);
  EXPECT_EQ(probe.frames, 10);
  const std::vector<uint8_t> first = DecodeFrame(path, 0);
  const std::vector<uint8_t> last = DecodeFrame(path, 9);
  ASSERT_EQ(first.size(), 64u * 48u * 3u);
  ASSERT_EQ(last.size(), first.size());
  EXPECT_NE(first, last);
}

TEST(VideoWriterTest, GifKeepsAtMostFiftyFramesASecond) {
  const std::string path = OutputPath("square.gif");
  // 125 fps: every third frame, 41.7 fps.
  auto writer = VideoWriter::Open(path, 64, 48, 125.0);
  ASSERT_TRUE(writer.ok()) << writer.status();
  EXPECT_EQ((*writer)->codec(), "gif");
  for (int i = 0; i < 10; ++i) {
    ASSERT_TRUE((*writer)->Write(MovingSquare(64, 48, i)).ok());
  }
  ASSERT_TRUE((*writer)->Finish().ok());
  EXPECT_EQ((*writer)->frames_written(), 4);  // 0, 3, 6, 9
  EXPECT_NEAR((*writer)->fps(), 125.0 / 3, 1e-9);
  const VideoProbe probe = ProbeVideo(path);
  ASSERT_TRUE(probe.ok);
  EXPECT_EQ(probe.frames, 4);
  EXPECT_EQ(probe.width, 64);
}

TEST(VideoWriterTest, RefusesWhatItCannotWrite) {
  auto writer = VideoWriter::Open(OutputPath("a.avi"), 64, 48, 20.0);
  EXPECT_TRUE(absl::IsInvalidArgument(writer.status()));
  EXPECT_THAT(writer.status().message(), HasSubstr("unknown extension"));
  writer = VideoWriter::Open("/nonexistent/dir/a.mp4", 64, 48, 20.0);
  EXPECT_TRUE(absl::IsInvalidArgument(writer.status()));
  EXPECT_THAT(writer.status().message(),
              HasSubstr("'/nonexistent/dir/a.mp4': cannot open it"));
  writer = VideoWriter::Open(OutputPath("odd.mp4"), 63, 48, 20.0);
  EXPECT_THAT(writer.status().message(), HasSubstr("must be even"));
  writer = VideoWriter::Open(OutputPath("still.mp4"), 64, 48, 0.0);
  EXPECT_THAT(writer.status().message(), HasSubstr("must be > 0"));

  writer = VideoWriter::Open(OutputPath("sizes.mp4"), 64, 48, 20.0);
  ASSERT_TRUE(writer.ok());
  absl::Status status = (*writer)->Write(MovingSquare(32, 48, 0));
  EXPECT_THAT(status.message(), HasSubstr("a frame of 32x48"));
  ASSERT_TRUE((*writer)->Finish().ok());
  EXPECT_TRUE(
      absl::IsFailedPrecondition((*writer)->Write(MovingSquare(64, 48, 0))));
}

}  // namespace
}  // namespace vantage
