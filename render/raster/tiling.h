// Tiling of large renders and the clip-space matrices that go with it.
//
// A frame bigger than the GL limits (or than the memory one framebuffer should take) is drawn
// as tiles, each with a projection narrowed to its sub-rectangle of the frustum, so the samples
// are the same pixel centres as in one big frame. The same transform maps OpenGL's [-1, 1]
// depth to a reversed [1, 0] range (near = 1), which keeps float depth precise far from the eye.
#pragma once

#include <array>
#include <vector>

namespace limn::render::raster {

using Mat4 = std::array<float, 16>;  // column-major, as OpenGL takes it

// A rectangle of pixels of the full frame, in limn's convention (row 0 at the top).
struct Tile {
  int x = 0, y = 0, width = 0, height = 0;
};

// Tiles covering width x height, none larger than maxSize in either direction, row-major from
// the top-left.
std::vector<Tile> makeTiles(int width, int height, int maxSize);

// Maps the full frame's clip space to the tile's, with reversed depth (to use with
// glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE), depth cleared to 0 and GL_GREATER).
Mat4 tileClipTransform(int fullWidth, int fullHeight, const Tile& tile);

Mat4 multiply(const Mat4& a, const Mat4& b);  // a * b

}  // namespace limn::render::raster
