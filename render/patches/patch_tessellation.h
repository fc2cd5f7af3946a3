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
};

struct TessellationStats {
  size_t patchesDrawn = 0;
  size_t patchesCulled = 0;     // facing away
  size_t patchesOffScreen = 0;  // outside the view
  size_t patchesSplit = 0;      // drawn as several domains (their edges wanted > maxEdgeFactor)
  size_t domains = 0;           // the units tessellated: whole patches and parts of split ones
  size_t transitionEdges = 0;   // domain edges split where a finer neighbour meets them
  size_t clampedEdges = 0;      // edge pieces that wanted more than maxEdgeFactor segments
  double dicingRate = 0;        // the rate used (coarser than asked when fitted to the budget)
};

struct PatchMesh {
  tessellate::TriangleMesh mesh;       // with triangleFaces and cornerUVs (Bfr's, per base face)
  std::vector<int32_t> trianglePatch;  // index into PatchSet::patches(), per triangle
  TessellationStats stats;
};

// Throws InputError(LimitExceeded, "maxTriangles") before evaluating the inside of any patch
// when the factors would make more than maxTriangles (unless fitToBudget), and Cancelled.
PatchMesh tessellatePatches(const PatchSet& patches, const Camera& camera,
                            const TessellationOptions& options, const CancelToken& cancel);

// True when the patch's control points (which hold it) all lie outside the view.
bool outsideTheView(const PatchSet& patches, const Patch& patch, const Camera& camera);

// True when `patch` is regular and every normal its B-spline points allow faces away from the
// eye (for each point the patch may cover): it cannot be seen from outside a closed surface.
bool facesAwayEverywhere(const PatchSet& patches, const Patch& patch, const Camera& camera);

}  // namespace limn::render::patches
