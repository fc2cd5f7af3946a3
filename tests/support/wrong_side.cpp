#include "tests/support/wrong_side.h"

#include <vector>

namespace limn::testing {

namespace {

// Per pixel: covered in both (alpha > 0.5) and on different sides; empty when the images do
// not match.
std::vector<char> wrongSideMap(const render::Image& color, const render::Image& reference) {
  if (reference.width != color.width || reference.height != color.height || color.channels != 4 ||
      reference.channels != 4) {
    return {};
  }
  const size_t pixels = static_cast<size_t>(color.width) * color.height;
  std::vector<char> out(pixels, 0);
  auto front = [](const float* p) { return p[0] > p[2]; };
  for (size_t i = 0; i < pixels; ++i) {
    const float* a = &color.pixels[4 * i];
    const float* b = &reference.pixels[4 * i];
    out[i] = a[3] > 0.5f && b[3] > 0.5f && front(a) != front(b);
  }
  return out;
}

}  // namespace

WrongSide wrongSidePixels(const render::Image& color, const render::Image& referenceColor) {
  const std::vector<char> map = wrongSideMap(color, referenceColor);
  if (map.empty()) return {-1, -1};
  WrongSide out;
  const int w = color.width, h = color.height;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      if (!map[static_cast<size_t>(y) * w + x]) continue;
      ++out.pixels;
      int neighbours = 0;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int nx = x + dx, ny = y + dy;
          if ((dx || dy) && nx >= 0 && ny >= 0 && nx < w && ny < h) {
            neighbours += map[static_cast<size_t>(ny) * w + nx];
          }
        }
      }
      out.inBands += neighbours >= 4;
    }
  }
  return out;
}

}  // namespace limn::testing
