// NormalAtlas: the limit normals of a LimitSurface baked into one texture, for drawing coarse
// geometry with the limit surface's shading (Shading::NormalMap in render/raster).
//
// Every face with a limit surface gets square charts of chartTexels x chartTexels texels: one
// for a quad (u, v in [0,1]^2) and for a triangle of Loop or Bilinear (u + v <= 1, the half
// i + j <= chartTexels - 1 of the chart), one per sub-face for the other faces (Catmull-Clark
// triangles and n-gons, whose Bfr parameterisation is split into quad sub-faces, each with
// normalised coordinates in [0,1]^2). Faces without a limit (holes) get none. Charts are laid
// out row by row in a grid, kGutter texels apart.
//
// Texel centres span the domain exactly: texel (i, j) of a chart holds the limit normal at
// (i, j) / (chartTexels - 1), so bilinear sampling anywhere in a face's domain reads only that
// face's texels. Texels outside every domain (the far half of a triangle's chart, gutters,
// unused grid cells) take the value of the nearest texel inside one (exact Euclidean nearest-
// feature transform), so every texel holds a unit normal.
//
// The image follows TriangleMesh's texture convention: row 0 at t = 0 (texcoords in
// triangle_mesh.h). Construction evaluates the surface in parallel (parallelFor); the atlas is
// immutable afterwards and may be shared between threads.
#pragma once

#include <cstddef>
#include <memory>
#include <vector>

#include "render/core/camera.h"
#include "render/core/image.h"
#include "render/core/vec.h"
#include "render/subdiv/limit_surface.h"

namespace limn::render::normalmap {

class NormalAtlas {
 public:
  static constexpr int kGutter = 1;  // texels between neighbouring charts
  static constexpr int kMinChartTexels = 4;

  // Throws std::invalid_argument when chartTexels < kMinChartTexels, and
  // InputError(LimitExceeded, "maxAtlasSide") when the grid of charts would be wider or taller
  // than maxSide texels.
  NormalAtlas(const subdiv::LimitSurface& surface, int chartTexels, int maxSide = 8192);

  // ---- Layout ----
  int chartTexels() const { return chartTexels_; }
  int chartCount() const { return static_cast<int>(charts_.size()); }
  int width() const { return image_->width; }
  int height() const { return image_->height; }
  // Number of charts NormalAtlas would make for `surface`.
  static int chartCountOf(const subdiv::LimitSurface& surface);
  // Side (in texels) of the atlas of `charts` charts of `chartTexels` texels each.
  static int sideFor(int charts, int chartTexels);

  // ---- Coordinates ----
  bool hasChart(int face) const;
  // Atlas coordinate in [0,1]^2 of face `face` at its Bfr parameter (u, v) (quads [0,1]^2,
  // triangles u + v <= 1, sub-faces as Bfr tiles them); (u, v) outside [0,1]^2 are clamped onto
  // it. Throws std::invalid_argument for a face out of range or without a chart.
  Vec2f coordinate(int face, Vec2 uv) const;
  // The same for sub-face `subFace` of a face split into sub-faces, at normalised sub-face
  // coordinates in [0,1]^2 (Bfr::Parameterization::ConvertNormalizedSubFaceToCoord); for other
  // faces subFace must be 0 and `st` is the face's (u, v).
  Vec2f subFaceCoordinate(int face, int subFace, Vec2 st) const;

  // ---- Texels ----
  // 3 channels, unit normals; at least 1 x 1 (a surface without any limit gives one texel, +Z).
  std::shared_ptr<const Image> image() const { return image_; }

 private:
  struct Chart {
    int face = 0;
    int subFace = -1;  // -1: the chart covers the face's own (u, v)
    bool triangle = false;
    int x = 0, y = 0;  // top-left texel in the image
  };

  void layOut(const subdiv::LimitSurface& surface, int maxSide);
  void bake(const subdiv::LimitSurface& surface);
  Vec2f chartCoordinate(const Chart& chart, double s, double t) const;

  int chartTexels_;
  std::vector<Chart> charts_;
  std::vector<int> firstChart_;  // per face, -1 for faces without one
  std::vector<OpenSubdiv::Bfr::Parameterization> parameterizations_;  // per face
  std::shared_ptr<Image> image_;
};

// How many texels each chart should have.
//
// chartTexelsForBudget: the largest chart side whose atlas stays within `texelBudget` texels in
// all and `maxSide` texels on a side (at least NormalAtlas::kMinChartTexels, even past the
// budget; at most maxChartTexels).
int chartTexelsForBudget(const subdiv::LimitSurface& surface, size_t texelBudget, int maxSide,
                         int maxChartTexels = 256);

// chartTexelsForCamera: enough texels that the face looking largest from `camera` gets about
// `texelsPerPixel` texels per pixel along its projected sides (limit positions of its corners,
// faces behind the eye left out), capped by chartTexelsForBudget(surface, texelBudget,
// maxSide, maxChartTexels). One size fits all charts, so faces smaller on screen get more
// texels per pixel than asked.
int chartTexelsForCamera(const subdiv::LimitSurface& surface, const Camera& camera,
                         double texelsPerPixel, size_t texelBudget, int maxSide,
                         int maxChartTexels = 256);

}  // namespace limn::render::normalmap
