// Image and ImageSet: float pixel buffers that raster/ and oracle/ produce and metrics/ and
// image/ consume (an ImageSet's supersampled coverage is a byte Mask: mask.h). Row 0 is the top
// row (see camera.h).
#pragma once

#include <cstddef>
#include <map>
#include <string>
#include <vector>

#include "render/core/mask.h"

namespace limn::render {

struct Image {
  int width = 0, height = 0, channels = 0;
  std::vector<float> pixels;  // row-major, interleaved channels

  Image() = default;
  Image(int w, int h, int c, float fill = 0.0f)
      : width(w), height(h), channels(c), pixels(static_cast<size_t>(w) * h * c, fill) {}

  bool empty() const { return pixels.empty(); }
  float& at(int x, int y, int c = 0) {
    return pixels[(static_cast<size_t>(y) * width + x) * channels + c];
  }
  float at(int x, int y, int c = 0) const {
    return pixels[(static_cast<size_t>(y) * width + x) * channels + c];
  }
};

// Names of the image passes; they are also the names clients use in "outputs".
namespace pass {
inline constexpr const char* kColor = "color";          // RGBA, shaded, alpha = coverage
inline constexpr const char* kMask = "mask";            // 1 channel, 1 covered / 0 not
inline constexpr const char* kDepth = "depth";          // 1 channel, linear depth, 0 = empty
inline constexpr const char* kNormal = "normal";        // 3 channels, unit world normal
inline constexpr const char* kWireframe = "wireframe";  // RGBA, colour with edges drawn over
inline constexpr const char* kContours = "contours";    // RGBA, colour with the contour drawn over
inline constexpr const char* kCage = "cage";        // RGBA, colour with the control cage drawn over
inline constexpr const char* kDiff = "diff";        // RGBA, heat map of the colour difference
inline constexpr const char* kPatches = "patches";  // RGBA, colour by patch level and kind
}  // namespace pass

// The passes of one rendering (approximation or reference) of one camera.
struct ImageSet {
  std::map<std::string, Image> passes;
  // Coverage at `supersample` times the resolution in each direction, for silhouette metrics.
  Mask supersampledMask;
  int supersample = 1;

  const Image* find(const std::string& name) const {
    auto it = passes.find(name);
    return it == passes.end() ? nullptr : &it->second;
  }
};

}  // namespace limn::render
