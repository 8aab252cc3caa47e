#ifndef VANTAGE_COMMON_ENV_FRAME_H_
#define VANTAGE_COMMON_ENV_FRAME_H_

#include <cstdint>
#include <vector>

namespace vantage {

// One rendered image: `height` rows of `width` packed RGB pixels, top row
// first, 8 bits per channel and no padding (rgb.size() == 3 * width *
// height).
struct Frame {
  int width = 0;
  int height = 0;
  std::vector<uint8_t> rgb;
};

}  // namespace vantage

#endif  // VANTAGE_COMMON_ENV_FRAME_H_
