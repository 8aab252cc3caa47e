#ifndef VANTAGE_TESTS_FAKES_VIDEO_PROBE_H_
#define VANTAGE_TESTS_FAKES_VIDEO_PROBE_H_

// Reads video files back with Debian's ffprobe and ffmpeg, independently of
// the code that wrote them.

#include <cstdint>
#include <string>
#include <vector>

namespace vantage {

struct VideoProbe {
  bool ok = false;
  int width = 0;
  int height = 0;
  int64_t frames = 0;  // decoded, not what the header claims
};

// `ffprobe -count_frames` of the first video stream.
VideoProbe ProbeVideo(const std::string& path);

// Frame `index` (0-based, in decoding order) as packed RGB24; empty if
// there is none.
std::vector<uint8_t> DecodeFrame(const std::string& path, int64_t index);

// Whether every pixel of a packed RGB image is the same.
bool IsUniform(const std::vector<uint8_t>& rgb);

}  // namespace vantage

#endif  // VANTAGE_TESTS_FAKES_VIDEO_PROBE_H_
