#include "tests/fakes/video_probe.h"

#include <cstdio>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"

namespace vantage {
namespace {

std::string Output(const std::string& command) {
  std::string out;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return out;
  char buffer[65536];
  size_t got;
  while ((got = fread(buffer, 1, sizeof(buffer), pipe)) > 0) {
    out.append(buffer, got);
  }
  pclose(pipe);
  return out;
}

}  // namespace

VideoProbe ProbeVideo(const std::string& path) {
  const std::string out = Output(absl::StrCat(
      "ffprobe -v error -count_frames -select_streams v:0 -show_entries "
      "stream=width,height,nb_read_frames -of csv=p=0 '",
      path, "'"));
  const std::vector<std::string> fields =
      absl::StrSplit(absl::StripAsciiWhitespace(out), ',');
  VideoProbe probe;
  probe.ok = fields.size() == 3 && absl::SimpleAtoi(fields[0], &probe.width) &&
             absl::SimpleAtoi(fields[1], &probe.height) &&
             absl::SimpleAtoi(fields[2], &probe.frames);
  return probe;
}

std::vector<uint8_t> DecodeFrame(const std::string& path, int64_t index) {
  const std::string out =
      Output(absl::StrCat("ffmpeg -v error -i '", path, "' -vf 'select=eq(n\\,",
                          index, ")' -vframes 1 -f rawvideo -pix_fmt rgb24 -"));
  return std::vector<uint8_t>(out.begin(), out.end());
}

bool IsUniform(const std::vector<uint8_t>& rgb) {
  for (size_t i = 3; i + 2 < rgb.size(); i += 3) {
    if (rgb[i] != rgb[0] || rgb[i + 1] != rgb[1] || rgb[i + 2] != rgb[2]) {
      return false;
    }
  }
  return true;
}

}  // namespace vantage
