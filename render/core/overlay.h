// LineOverlay: lines drawn over the colour image, each overlay making one extra output pass
// (the control cage, contour curves). The rasteriser draws them; whoever computes the lines
// (pipeline, silhouette) fills this in world space and knows nothing of OpenGL.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "render/core/vec.h"

namespace limn::render {

struct LineOverlay {
  std::string pass;                            // name of the pass it makes, e.g. "cage", "contours"
  std::vector<Vec3f> points;                   // world space, two per segment
  std::vector<std::array<uint8_t, 4>> colors;  // RGBA, one per segment
  // true: parts behind the drawn surface are hidden (depth test with a small bias so lines
  // lying ON the surface stay visible); false: drawn over everything.
  bool occluded = true;

  size_t segmentCount() const { return points.size() / 2; }
};

}  // namespace limn::render
