// SurfaceProbe: what a coarse grid of limit samples says about each face as one camera sees it.
// Whether the face's facing changes (so it may carry a silhouette), and how finely each of its
// edges must be split for a chord error of so many pixels. Both reference paths size their
// tessellations from it: the dense triangles of renderReference and Embree's grids.
//
// A chord of length s on a curve of radius R deviates from it by s^2 / (8 R), so an edge of
// length L needs L / sqrt(8 e R) segments for error e. L is the edge's 3D length at the nearer
// end's pixel scale, not its projected length: at the silhouette an edge running towards the
// viewer looks short but is curved, and its chords are what stick out of the outline. 1/R is the
// larger of the surface's curvature (normal turn per length between neighbouring samples) and
// the edge curve's own (second differences along it, which sees boundary curves bend), doubled
// because samples miss peaks between them.
#pragma once

#include <vector>

#include "render/core/camera.h"
#include "render/subdiv/limit_surface.h"

namespace limn::render::oracle {

struct FaceProbe {
  bool probed = false;         // false for faces without a limit surface
  double gMin = 1, gMax = -1;  // range of cos(normal, view direction) over the samples
  double normalSpread = 0;     // largest |n_i - n_j| between neighbouring samples
  bool silhouette = false;     // facing changes sign, or nears zero closer than it varies
  // Per face edge (edge k runs from corner k to corner k + 1): segments needed for a chord error
  // of one pixel; for error e divide by sqrt(e).
  std::vector<double> segmentsAtOnePixel;
  std::vector<double> lengthPx;  // 3D length at the nearer end's pixel scale
};

// All faces, on all threads.
std::vector<FaceProbe> probeFaces(const subdiv::LimitSurface& surface, const Camera& camera);

}  // namespace limn::render::oracle
