// OverlayBuffers: the segments of a render's LineOverlays on the GPU, one vertex buffer for all
// overlays (each vertex carries its segment's colour), drawn one overlay at a time as GL_LINES
// for the line program's geometry shader to widen. Created once per Rasterizer and refilled for
// every render that has overlays.
#pragma once

#include <vector>

#include "render/core/overlay.h"
#include "render/raster/gl_api.h"

namespace limn::render::raster {

// Throws std::invalid_argument for an overlay the rasteriser cannot draw: an odd number of
// points, colours not one per segment, non-finite points, an empty pass name, or a name that is
// a built-in pass (color, mask, depth, normal, wireframe) or repeats another overlay's.
void validateOverlays(const std::vector<LineOverlay>& overlays);

class OverlayBuffers {
 public:
  OverlayBuffers();
  ~OverlayBuffers();
  OverlayBuffers(const OverlayBuffers&) = delete;
  OverlayBuffers& operator=(const OverlayBuffers&) = delete;

  // Uploads every overlay's segments; the overlays must have passed validateOverlays.
  void upload(const std::vector<LineOverlay>& overlays);
  // Draws the segments of overlay `index` of the last upload.
  void draw(size_t index) const;

 private:
  GLuint array_ = 0, vertices_ = 0;
  std::vector<GLint> first_;     // first vertex of each overlay
  std::vector<GLsizei> counts_;  // its number of vertices
};

}  // namespace limn::render::raster
