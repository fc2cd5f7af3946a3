// Limit positions and tangents of the last level of a uniform refinement, from OpenSubdiv's Sdc
// limit masks applied with buffers sized for each vertex.
//
// Far::PrimvarRefiner::Limit (OpenSubdiv 3.5) sizes one buffer for every vertex's mask as
// 1 + 2 x (the level's largest edge count), assuming a vertex has no more faces than edges. At
// a non-manifold vertex it may have twice as many: after one level, the midpoint of an edge
// shared by n quads has n + 2 edges and 2n faces, and Far writes the crease tangent's face
// weights past its buffer (a heap corruption; n = 100 killed limn's server). The masks are
// right; only their buffer is too small, so limn applies them itself.
#pragma once

#include <opensubdiv/far/topologyRefiner.h>

#include <vector>

#include "render/subdiv/far_point.h"

namespace limn::render::subdiv {

// `src` holds the last level's refined points; `limit`, `du` and `dv` get one entry per vertex
// of that level (tangents are zero where the vertex has no edges).
void limitOfLastLevel(const OpenSubdiv::Far::TopologyRefiner& refiner, const FarPoint* src,
                      std::vector<FarPoint>& limit, std::vector<FarPoint>& du,
                      std::vector<FarPoint>& dv);

}  // namespace limn::render::subdiv
