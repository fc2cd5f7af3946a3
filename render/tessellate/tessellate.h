// The approximations of the limit surface that limn draws.
//   coarse:   the control cage itself, polygons fanned into triangles;
//   uniform:  the cage refined `level` times (OpenSubdiv's uniform refinement or limn's own
//             rules), optionally pushed to the limit;
//   adaptive: each face's limit surface tessellated with per-edge rates chosen from the
//             projected edge length, shared edges sharing their rate and their vertices, so the
//             mesh is watertight.
#pragma once

#include <functional>

#include "render/core/camera.h"
#include "render/core/cancel.h"
#include "render/subdiv/limit_surface.h"
#include "render/tessellate/triangle_mesh.h"

namespace limn::render::tessellate {

TriangleMesh tessellateCoarse(const subdiv::LimitSurface& surface);

// Which implementation of the subdivision rules refines a uniform mesh: OpenSubdiv's Far, or
// limn's own (render/rules) by masks or, for Catmull-Clark, in factored form. All three give
// the same vertices in the same order where their rules agree (docs/engine.md). Auto, the
// fastest that takes the mesh: the masks for manifold Catmull-Clark and Loop meshes (their
// levels run on halfedges, in parallel), OpenSubdiv for bilinear and non-manifold meshes.
enum class UniformEngine { Auto, OpenSubdiv, Masks, Factored };

struct UniformOptions {
  int level = 3;
  UniformEngine engine = UniformEngine::Auto;
  // false: vertices stay where refinement put them (limitPositions holds their limit);
  // true: every vertex is moved to its limit position. Normals are the limit normals either way.
  bool pushToLimit = false;
  size_t maxTriangles = 8'000'000;
  // Optional: where the time went (benchmarks).
  struct Stages {
    double refineMs = 0;  // topology and refined points of every level
    double limitMs = 0;   // limit positions and normals of the last level
    double meshMs = 0;    // the triangles, lines and float buffers the rasteriser takes
  }* stages = nullptr;
};

// Throws InputError(LimitExceeded, "maxTriangles") if the result would exceed maxTriangles,
// and InputError(InvalidMesh) when limn's own rules cannot take the mesh (non-manifold).
TriangleMesh tessellateUniform(const subdiv::LimitSurface& surface, const UniformOptions& options);
// OpenSubdiv, not pushed to the limit.
TriangleMesh tessellateUniform(const subdiv::LimitSurface& surface, int level, size_t maxTriangles);

struct AdaptiveOptions {
  double dicingRate = 1.0;  // target edge length in pixels
  int maxEdgeRate = 128;    // segments per edge at most
  int minEdgeRate = 1;      // used for faces outside the view or facing away
  size_t maxTriangles = 8'000'000;
  // Over maxTriangles (counted from the edge rates before anything is evaluated): false throws
  // LimitExceeded naming `stage`; true scales every rate down until the mesh fits (the
  // reference's own tessellation, which must not refuse what a method can draw) and reports the
  // factor in *ratesScaled.
  bool fitToBudget = false;
  const char* stage = "adaptive";
  const char* remedy = "raise params.dicingRate";  // said in the 413; "" for none
  double* ratesScaled = nullptr;
  // Optional lower bound on the segments of base-level edge e (then capped by maxEdgeRate),
  // applied whether or not its faces are culled. Projected lengths are foreshortened where the
  // surface turns away at the silhouette; the reference bounds those edges by their 3D length.
  std::function<int(int edge)> minSegments;
  // Faces whose contour comes within kCrowdedContourPx of another part's contour in the image
  // are diced this many times finer (contour_proximity.h); 1 leaves them as they are.
  double crowdedContourScale = 1;
};

TriangleMesh tessellateAdaptive(const subdiv::LimitSurface& surface, const Camera& camera,
                                const AdaptiveOptions& options, const CancelToken& cancel);

}  // namespace limn::render::tessellate
