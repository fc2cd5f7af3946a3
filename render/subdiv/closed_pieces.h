// Which faces belong to a closed piece of the mesh, and which way that piece is wound.
//
// A ray's first hit on a closed surface enters it, so on a closed piece the side facing away
// from the eye is hidden, and the methods cull it (adaptive, silhouette, patches). But a piece
// is only "closed" as the methods need it when it is closed by itself, and "facing away" is
// judged by the limit normal, which follows the faces' winding: a piece modelled inside-out
// (every face wound clockwise seen from outside, common in production models) has its visible
// side facing "away". Both are decided per connected piece here, not for the mesh as a whole:
// a plant's open leaves no longer stop its closed stem from being culled, and an inside-out
// piece has its other side culled rather than its visible one (the inside-out humanoid's
// silhouette was 1.75 px off with 6x the triangles).
#pragma once

#include <opensubdiv/far/topologyLevel.h>

#include <cstdint>
#include <vector>

#include "render/core/vec.h"

namespace limn::render::subdiv {

// Per base face: +1 on a closed piece wound counter-clockwise seen from outside (its enclosed
// volume is positive), -1 on a closed piece wound the other way, 0 on a piece that is open,
// non-manifold, has a hole, or encloses no volume. The facing to cull by is then
// side * dot(normal, view) > 0. A piece is the faces connected through shared edges.
std::vector<int8_t> hiddenSideOfFaces(const OpenSubdiv::Far::TopologyLevel& base,
                                      const std::vector<Vec3>& points);

}  // namespace limn::render::subdiv
