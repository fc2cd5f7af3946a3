#include "render/raster/tiling.h"

#include <algorithm>
#include <stdexcept>

namespace limn::render::raster {

std::vector<Tile> makeTiles(int width, int height, int maxSize) {
  if (width <= 0 || height <= 0 || maxSize <= 0) {
    throw std::invalid_argument("raster: frame and tile sizes must be positive");
  }
  std::vector<Tile> tiles;
  for (int y = 0; y < height; y += maxSize) {
    for (int x = 0; x < width; x += maxSize) {
      tiles.push_back({x, y, std::min(maxSize, width - x), std::min(maxSize, height - y)});
    }
  }
  return tiles;
}

Mat4 tileClipTransform(int fullWidth, int fullHeight, const Tile& tile) {
  // OpenGL's window y goes up: the tile's bottom row in the full frame's GL coordinates.
  const double glX = tile.x;
  const double glY = fullHeight - tile.y - tile.height;
  // x_tile = x * W / w + (W - 2 x0 - w) / w * clip_w, and likewise for y: full-frame pixel
  // x0 + i lands on tile pixel i.
  const double sx = static_cast<double>(fullWidth) / tile.width;
  const double sy = static_cast<double>(fullHeight) / tile.height;
  const double ox = (fullWidth - 2.0 * glX - tile.width) / tile.width;
  const double oy = (fullHeight - 2.0 * glY - tile.height) / tile.height;
  Mat4 m{};
  m[0] = static_cast<float>(sx);
  m[5] = static_cast<float>(sy);
  m[12] = static_cast<float>(ox);
  m[13] = static_cast<float>(oy);
  // Reversed depth: z' = (w - z) / 2 maps near (z = -w) to w and far (z = w) to 0.
  m[10] = -0.5f;
  m[14] = 0.5f;
  m[15] = 1.0f;
  return m;
}

Mat4 multiply(const Mat4& a, const Mat4& b) {
  Mat4 r{};
  for (int col = 0; col < 4; ++col) {
    for (int row = 0; row < 4; ++row) {
      double sum = 0.0;
      for (int k = 0; k < 4; ++k) sum += static_cast<double>(a[k * 4 + row]) * b[col * 4 + k];
      r[col * 4 + row] = static_cast<float>(sum);
    }
  }
  return r;
}

}  // namespace limn::render::raster
