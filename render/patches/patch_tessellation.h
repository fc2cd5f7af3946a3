// tessellatePatches(): a PatchSet drawn for a camera as one watertight triangle mesh.
//
// Each patch edge gets a tessellation factor from its projected size (about `dicingRate`
// pixels per segment, at most maxEdgeFactor); a patch whose edges want more is cut into 4^k
// domains first, as deeper isolation would cut it. Factors and vertices are shared by construction:
// patch corners are welded first; an edge whose midpoint is the corner of a finer neighbour
// (Far's transition edges, where isolation levels meet) is split there, and each piece is
// tessellated once, keyed by its welded end points, so both sides use the same vertices. The
// inside of a patch is a grid stitched to its edges. Hidden patches are left out: those whose
// control points lie outside the view, and, on a closed surface seen from outside, regular
// patches that face away from the eye everywhere (every normal the 4 x 4 B-spline points
// allow).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "render/core/camera.h"
#include "render/core/cancel.h"
#include "render/patches/patch_set.h"
#include "render/tessellate/triangle_mesh.h"

namespace limn::render::patches {

struct TessellationOptions {
  double dicingRate = 1.0;  // target segment length in pixels
  int maxEdgeFactor = 64;   // segments per patch edge at most
  bool cullHidden = true;
  size_t maxTriangles = 8'000'000;
  // Over maxTriangles: true coarsens the dicing rate until the mesh fits (reported in
  // TessellationStats::dicingRate); false throws InputError(LimitExceeded).
  bool fitToBudget = false;
  // Domains whose contour comes within kCrowdedContourPx of another part's contour in the image
  // are diced this many times finer (tessellate/contour_proximity.h); 1 leaves them as they are.
  double crowdedContourScale = 1;
};

struct TessellationStats {
  size_t patchesDrawn = 0;
  size_t patchesCulled = 0;     // facing away
  size_t patchesOffScreen = 0;  // outside the view
  size_t patchesSplit = 0;      // drawn as several domains (their edges wanted > maxEdgeFactor)
  size_t domains = 0;           // the units tessellated: whole patches and parts of split ones
  size_t transitionEdges = 0;   // domain edges split where a finer neighbour meets them
  size_t clampedEdges = 0;      // edge pieces that wanted more than maxEdgeFactor segments
  size_t crowdedDomains = 0;    // diced finer: their contour runs close to another part's
  double dicingRate = 0;        // the rate used (coarser than asked when fitted to the budget)
};

// A part of one patch tessellated as a unit: patch-local (s, t) = origin + a * axisA + b * axisB
// for the domain's own (a, b) in the unit square or triangle.
struct PatchDomain {
  int patch = 0;  // index into PatchSet::patches()
  bool triangle = false;
  Vec2 origin{0, 0}, axisA{1, 0}, axisB{0, 1};

  Vec2 toPatch(Vec2 ab) const {
    return {origin.x + ab.x * axisA.x + ab.y * axisB.x, origin.y + ab.x * axisA.y + ab.y * axisB.y};
  }
  // One of the four children of a split: quadrants, or for triangles the three corner
  // triangles and the inverted middle one (same orientation).
  PatchDomain child(int k) const;
  int corners() const { return triangle ? 3 : 4; }
};

// One piece of a domain's side (from corner k to corner k + 1): it ends at fraction `end` of
// the side (the last piece at 1) and is cut into `segments` equal parameter steps.
struct SidePiece {
  double end = 1;
  int segments = 1;
};

// The tessellation factors of every drawn domain, equal on both sides of every shared edge: a
// side is one piece, or several where finer neighbours' corners lie on it (transition edges).
// The pieces of one side add up to at most maxEdgeFactor segments.
struct TessellationPlan {
  std::vector<PatchDomain> domains;
  std::vector<std::array<std::vector<SidePiece>, 4>> sides;  // per domain; 3 used by triangles
  size_t triangles = 0;                                      // what tessellatePatches() makes of it
  TessellationStats stats;
};

// Where a vertex was evaluated: patch-local (s, t), and the point its normal is taken towards
// where the derivatives vanish (its domain's centre).
struct VertexSource {
  int32_t patch = 0;
  Vec2 st, towards;
};

struct PatchMesh {
  tessellate::TriangleMesh mesh;       // with triangleFaces and cornerUVs (Bfr's, per base face)
  std::vector<int32_t> trianglePatch;  // index into PatchSet::patches(), per triangle
  std::vector<VertexSource> vertexSources;  // per vertex
  TessellationStats stats;
};

// Throws InputError(LimitExceeded, "maxTriangles") before evaluating the inside of any patch
// when the factors would make more than maxTriangles (unless fitToBudget), and Cancelled.
PatchMesh tessellatePatches(const PatchSet& patches, const Camera& camera,
                            const TessellationOptions& options, const CancelToken& cancel);

// `mesh` (made by tessellatePatches) moved onto the patches' current control points, for an
// animation frame: every vertex re-evaluated where it was made, in parallel; triangles, factors
// and the patches left out are kept, so its dicing rate holds only as far as the points move.
// Checks `cancel`.
void reevaluatePatchMesh(const PatchSet& patches, PatchMesh& mesh, const CancelToken& cancel);

// The factors tessellatePatches() uses, without evaluating the inside of any patch (the GPU
// path dices them in tessellation shaders). Same errors and budget fitting.
TessellationPlan planPatchTessellation(const PatchSet& patches, const Camera& camera,
                                       const TessellationOptions& options,
                                       const CancelToken& cancel);

// True when the patch's control points (which hold it) all lie outside the view.
bool outsideTheView(const PatchSet& patches, const Patch& patch, const Camera& camera);

// True when `patch` is regular and every normal its B-spline points allow faces away from the
// eye (for each point the patch may cover): it cannot be seen from outside a closed surface.
// hiddenSide -1 (an inside-out piece, PatchSet::hiddenSide): the normals are taken reversed.
bool facesAwayEverywhere(const PatchSet& patches, const Patch& patch, const Camera& camera,
                         int hiddenSide = 1);

}  // namespace limn::render::patches
