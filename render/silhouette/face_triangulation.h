// Local re-triangulation of one face (step 4 of the silhouette method), done in the face's
// parameter plane where the face is a convex polygon: the boundary (corners and the shared
// edge points, so neighbours keep identical edges and no T-junction opens) is cut along each
// contour curve into regions, and every region is ear-clipped, then flipped to its constrained
// Delaunay triangulation (no fans of long chords). Points keep their positions on the limit
// surface; only the connectivity is decided in (u, v).
#pragma once

#include <array>
#include <vector>

#include "render/core/vec.h"

namespace limn::render::silhouette {

struct CurvePath {
  int from = -1, to = -1;     // boundary point indices
  std::vector<int> interior;  // point indices of its samples, in order from `from`
};

// Points 0 .. boundaryCount-1 form the boundary, counter-clockwise in uv; the curves join
// boundary points through further points. Returns triangles (point indices), counter-clockwise
// in uv. Curves must not cross each other; each boundary point ends at most one curve.
std::vector<std::array<int, 3>> triangulateFace(const std::vector<Vec2>& uv, int boundaryCount,
                                                const std::vector<CurvePath>& curves);

// Ear clipping of one simple polygon given counter-clockwise, then Lawson's flips inside it to
// its constrained Delaunay triangulation; vertices on a straight run are kept as triangle
// corners (they are edge points shared with a neighbour).
void earClip(const std::vector<Vec2>& uv, std::vector<int> polygon,
             std::vector<std::array<int, 3>>& triangles);

}  // namespace limn::render::silhouette
