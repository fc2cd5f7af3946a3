// How each pass of an ImageSet maps to 8-bit pixels for PNG. Kept apart from the file I/O so the
// mapping (which clients see in every PNG) is one small, testable function.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "render/core/image.h"

namespace limn::render::image {

// Grey level of the farthest covered depth in a depth PNG; the nearest is 1 (white) and empty
// pixels are 0 (black), so the farthest surface stays distinguishable from the background.
inline constexpr float kFarthestDepthGrey = 0.2f;

// The pass as 8-bit values with the same channel count (1, 3 or 4), row 0 at the top: the
// shaded passes (color, wireframe, contours, cage, patches: linear light) are written as sRGB,
// alpha as it is; mask, diff and unknown passes clamp [0, 1]; depth and normal are remapped as
// documented in encode.h.
std::vector<uint8_t> to8Bit(const Image& image, const std::string& passName);

}  // namespace limn::render::image
