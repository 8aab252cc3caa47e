#ifndef VANTAGE_DEPLOY_OBSERVE_VIDEO_WRITER_H_
#define VANTAGE_DEPLOY_OBSERVE_VIDEO_WRITER_H_

// Encodes rendered frames into a video file with FFmpeg's libraries: MP4
// with H.264 (MPEG-4 part 2 if this FFmpeg has no H.264 encoder), or an
// animated GIF. The FFmpeg headers stay in the .cc.

#include <cstdint>
#include <memory>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "common/env/frame.h"

namespace vantage {

class VideoWriter {
 public:
  // The container follows `path`'s extension: .mp4 or .gif (any case);
  // anything else is InvalidArgument, and so are sizes that are not even
  // (YUV 4:2:0 halves both) or outside [16, 8192], and a frame rate that
  // is not positive. A file that cannot be written is InvalidArgument
  // naming it. GIF delays are whole centiseconds and players slow down
  // anything under 2, so a GIF keeps every k-th frame for at most 50 fps.
  static absl::StatusOr<std::unique_ptr<VideoWriter>> Open(
      const std::string& path, int width, int height, double fps);
  // Without Finish the file is left incomplete.
  ~VideoWriter();
  VideoWriter(const VideoWriter&) = delete;
  VideoWriter& operator=(const VideoWriter&) = delete;

  // `frame` must have the size given to Open.
  absl::Status Write(const Frame& frame);
  // Flushes the encoder and writes the trailer; nothing may follow.
  absl::Status Finish();

  // Frames in the file, and its frame rate (lower than Open's for a GIF
  // that drops frames).
  int64_t frames_written() const { return frames_written_; }
  double fps() const { return fps_ / keep_every_; }
  // The encoder's name ("libx264", "mpeg4", "gif").
  const std::string& codec() const { return codec_; }

 private:
  struct Av;
  VideoWriter(std::unique_ptr<Av> av, int width, int height, double fps,
              int keep_every, std::string codec);
  // Sends `frame` (nullptr: the end) and writes the packets that come out.
  absl::Status Encode(bool flush);

  std::unique_ptr<Av> av_;
  int width_;
  int height_;
  double fps_;
  int keep_every_;
  std::string codec_;
  int64_t frames_seen_ = 0;
  int64_t frames_written_ = 0;
  bool finished_ = false;
};

}  // namespace vantage

#endif  // VANTAGE_DEPLOY_OBSERVE_VIDEO_WRITER_H_
