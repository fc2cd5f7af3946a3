// Concave contours (part of step 4 of the silhouette method). The coarse faces are flat
// triangles through points of the limit surface; where the surface is concave along an edge,
// the chord lies OUTSIDE it, and next to the contour such a chord either pokes past the exact
// outline (into a torus's hole, say) or hides part of it. The correction is propagated two
// rings out from the contour faces: every edge of a contour face or of a face near one (see
// ChordOptions::rings) whose chord lies outside the surface by more than `tolerancePx` (projected)
// gets uniform points along its limit curve, enough to bring the chord's sag under the tolerance
// (sag falls with the square of the segment count); such ring faces whose centre lies outside
// the surface likewise get interior points. Chords inside the surface (convex regions) stay:
// the exact contour curves already bound the outline there. An open piece has no inside: both
// its sides are checked.
#pragma once

#include <vector>

#include "render/core/camera.h"
#include "render/silhouette/contour_search.h"
#include "render/subdiv/limit_surface.h"

namespace limn::render::silhouette {

// Which side of a face's surface a chord must not lie on: outside a closed piece (its
// LimitSurface::outwardSign), and either side of an open one (0), whose two sides can both be
// seen; the inner wall of a thin open shell (a bottle's neck seen from the side) bulges out
// through the outer wall where its chords span its concave flare.
inline int outsideSide(const subdiv::LimitSurface& surface, int face) {
  return surface.hiddenSide(face) != 0 ? surface.outwardSign(face) : 0;
}

// How far `chordPoint` lies on the `side` (outsideSide) of the surface at `sample`, in pixels
// (0 when on the other side).
double outsidePixels(const Camera& camera, const Vec3& chordPoint,
                     const subdiv::LimitSample& sample, int side);

struct ChordOptions {
  double tolerancePx = 0.1;
  int maxSegments = 32;  // per edge, and per side of a face's interior
  // Rings of faces around the contour faces that are checked. Two, because where an outline
  // passes close in front of another part (a torus's hole seen nearly closed) the faces two
  // rings out still project next to it.
  int rings = 2;
  int maxFaceSplits = 64;  // interior edge splits per face (face_refinement.h)
  // ... and per face at an infinitely sharp corner, where the surface comes to a cusp whose
  // flanks bend within a small corner of (u, v), so that midpoint splits need many more steps.
  // Not everywhere: on smooth dense meshes more splits chased sub-tolerance sags into slivers
  // (the 1,280-face triangle sphere: twice the triangles and no closer).
  int maxCuspFaceSplits = 256;
};

struct ChordRefinement {
  std::vector<int> edgeRates;      // per base edge: uniform segments added (0: none)
  std::vector<int> interiorRates;  // per face: inner tessellation rate (0: none)
  size_t refinedEdges = 0, refinedFaces = 0;
};

// True when face `face` holds a crossing of g on one of its edges (as seen from that face).
std::vector<bool> contourFaces(const subdiv::LimitSurface& surface, const ContourSearch& search);

// Adds the uniform points to search.edgePoints (as points with no crossing) and returns the
// rates it chose. Outline edges (which already carry uniform points) are left as they are.
ChordRefinement refineConcaveChords(const FaceDomains& domains, const Camera& camera,
                                    const std::vector<bool>& contourFace,
                                    const ChordOptions& options, ContourSearch& search);

}  // namespace limn::render::silhouette
