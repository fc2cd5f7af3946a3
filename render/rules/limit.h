// Limit masks: where each vertex of a level ends up on the limit surface, and the surface's
// tangent plane there, each from the vertex's one-ring alone (no further refinement), for
// Catmull-Clark and Loop.
//
// Positions: an interior (smooth or dart) vertex takes the dominant left eigenvector of its
// subdivision matrix (Catmull-Clark on quads: n^2 v + 4 sum(edge neighbours) + sum(diagonal
// neighbours), over n(n+5) -- the bicubic B-spline's 1/36 [1 4 1] x [1 4 1] at n = 4; Loop:
// (1 - n chi) v + chi sum(neighbours), chi = 1 / (n + 3/(8 beta(n)))); a crease or boundary
// vertex the cubic B-spline's (1/6, 4/6, 1/6) along its crease; a corner stays.
// Tangents: interior vertices use the eigenvectors of the subdivision matrix (cosine and sine
// weights, Halstead et al. 1993 / Loop 1987); crease and boundary vertices the crease
// direction and a cross tangent from the boundary eigen-analysis (Hoppe et al. 1994, Biermann
// et al. 2000 for Catmull-Clark; Loop's boundary eigenvectors), oriented into the surface;
// corners the directions of the two edges of a face. These are the formulas OpenSubdiv's
// PrimvarRefiner::Limit uses, with the same conventions, so their normals agree.
//
// Like OpenSubdiv's, the masks read the rule of each vertex at this level: a crease that is
// still semi-sharp is taken as sharp, so the result is the true limit only once every
// sharpness has decayed (after ceil(max sharpness) levels). A Catmull-Clark level with faces
// that are not quads is refined once first (a vertex and its child share their limit).
//
// Where the limit normal is not unique -- a vertex on an interior crease (one tangent plane on
// each side) or a corner (each face sees its own plane) -- each face corner gets the normal of
// its side (cornerNormals). The vertex's own tangents follow OpenSubdiv's convention over the
// orderedRing() order: at a crease, the side counter-clockwise from the first sharp edge to
// the second; at a corner, the ring's first face. Where OpenSubdiv's ring starts elsewhere
// (its own face order at refined levels) it returns another of the corner normals.
#pragma once

#include <vector>

#include "render/core/vec.h"
#include "render/rules/refine.h"

namespace limn::render::rules {

struct Limit {
  std::vector<Vec3> positions;           // per vertex
  std::vector<Vec3> tangent1, tangent2;  // per vertex, scaled as OpenSubdiv scales them
  std::vector<Vec3> normals;             // per vertex, unit cross(tangent1, tangent2) or zero
  std::vector<Vec3> cornerNormals;       // per face corner (topology.faceOffsets), unit or zero
};

// cornerNormals false leaves Limit::cornerNormals empty (a mesh drawn with vertex normals
// does not need them). Parallel; the result does not depend on the number of threads.
Limit limitOf(const Level& level, bool cornerNormals = true);

}  // namespace limn::render::rules
