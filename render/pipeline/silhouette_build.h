// The silhouette method's front half, shared by run() (method "silhouette" of POST /v1/render)
// and runContours() (POST /v1/silhouette): whether to pre-subdivide, the method's options from
// the request's params, the silhouette mesh, and the warnings its stats call for. One place, so
// that the curves /v1/silhouette returns are the ones /v1/render draws.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "render/core/camera.h"
#include "render/core/cancel.h"
#include "render/silhouette/presubdivide.h"
#include "render/silhouette/silhouette_mesh.h"
#include "render/subdiv/limit_surface.h"

namespace limn::render::pipeline {

// The request's params of the silhouette method.
struct SilhouetteParams {
  silhouette::Presubdivide presubdivide = silhouette::Presubdivide::Auto;
  int searchSteps = 5;    // bisection steps of the edge search
  int curveSamples = 32;  // samples per contour curve at most
  silhouette::CurveMode contour = silhouette::CurveMode::Exact;
};

struct SilhouetteBuild {
  // The mesh refined once, when it was (same limit surface, finer cage); the curves' faces
  // and (u, v) refer to it. Null when the method ran on the request's surface.
  std::unique_ptr<subdiv::LimitSurface> presubdivided;
  int presubdivisionLevels = 0;  // refinement steps that made it
  silhouette::SilhouetteMesh built;

  // The surface the curves were found on.
  const subdiv::LimitSurface& drawn(const subdiv::LimitSurface& original) const {
    return presubdivided ? *presubdivided : original;
  }
};

// Refines `surface`'s mesh under "auto" when presubdivisionReason() gives a reason (once, then
// again while chordDeviationPx() is over kMaxChordDeviationPx: presubdivide.h), once under 1
// and never under 0; then builds the silhouette mesh. Appends the warnings for faces with an odd
// crossing count and for exact samples that found no root.
SilhouetteBuild buildSilhouette(const subdiv::LimitSurface& surface, const Camera& camera,
                                const SilhouetteParams& params, size_t maxTriangles,
                                const CancelToken& cancel, std::vector<std::string>& warnings);

}  // namespace limn::render::pipeline
