// Mask: coverage at one byte a pixel (1 covered, 0 not), the type of the supersampled masks
// that raster/ and oracle/ produce and metrics/ compares. Those are large (S = 8 at 1024^2 is
// 8192^2 pixels: 64 MiB as bytes, where float pixels took 256 MiB, and a comparison keeps one
// per method until it is measured), so they hold nothing but the coverage. Row 0 is the top row
// (see camera.h).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace limn::render {

struct Mask {
  int width = 0, height = 0;
  std::vector<uint8_t> covered;  // row-major, 1 covered / 0 not

  Mask() = default;
  Mask(int w, int h) : width(w), height(h), covered(static_cast<size_t>(w) * h, 0) {}

  bool empty() const { return covered.empty(); }
  uint8_t& at(int x, int y) { return covered[static_cast<size_t>(y) * width + x]; }
  uint8_t at(int x, int y) const { return covered[static_cast<size_t>(y) * width + x]; }
};

}  // namespace limn::render
