// The steps of one method for one camera that run() (one method, its own reference) and
// compare() (several methods, one reference per camera) share, so that a row of a comparison
// is computed exactly as the same method's render:
//   approximateMethod  surface + camera -> the method's TriangleMesh (and its finer cage)
//   drawMethod         ... + raster passes (all the metrics need, when measured)
//   measureDrawing     a drawing against a reference of the same camera -> Metrics (measure.h's
//                      image metrics and the geometric error)
// Internal to render/pipeline; callers outside use run(), approximate() and compare().
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "render/core/camera.h"
#include "render/core/cancel.h"
#include "render/core/image.h"
#include "render/core/overlay.h"
#include "render/metrics/metrics.h"
#include "render/oracle/reference.h"
#include "render/pipeline/render_job.h"
#include "render/subdiv/limit_surface.h"
#include "render/tessellate/triangle_mesh.h"

namespace limn::render::pipeline {

// Whether a method (and the reference) evaluates the Bfr limit surface: all but uniform
// refinement, which refines the cage itself, without a reference. Where it does, the pipeline
// prepares the surface up front so that surfaceMs times it; elsewhere the surface builds itself
// on first use, if any.
inline bool evaluatesLimitSurface(Method method, bool reference) {
  return reference || method != Method::Uniform;
}

// One method as a request chose it; the mesh is the client's (the cage overlay draws it).
struct MethodChoice {
  const mesh::ControlMesh& mesh;
  Method method;  // Limit only for checkMethod: the others draw a mesh
  const MethodParams& params;
  Shading shading;
  const Outputs& outputs;
};

// What a method made of the surface, before any raster.
struct Approximated {
  tessellate::TriangleMesh mesh;
  // The silhouette method's pre-subdivided copy (same limit surface, finer cage), when made:
  // the mesh's faces and (u, v) refer to it.
  std::unique_ptr<subdiv::LimitSurface> presubdivided;
  std::vector<LineOverlay> overlays;  // the outputs drawn over the colour: contours, cage
  // The patches method's mesh coloured by patch (outputs.patches), drawn as its own pass.
  std::optional<tessellate::TriangleMesh> patchImageMesh;
  Stats stats;  // triangles, vertices and the silhouette method's counts
  double approxMs = 0;
  std::vector<std::string> warnings;

  // The surface the mesh's (face, u, v) refer to.
  const subdiv::LimitSurface& drawnOn(const subdiv::LimitSurface& original) const {
    return presubdivided ? *presubdivided : original;
  }
};

// The method's approximation (checks of `choice` against `limits` are the caller's: checkMethod).
// `context` (null for a mesh to download) serves the patches' GPU tessellator.
Approximated approximateMethod(const MethodChoice& choice, const JobLimits& limits,
                               const subdiv::LimitSurface& surface, const Camera& camera,
                               RenderContext* context, const CancelToken& cancel);

// The patches method on a patch table already built (animation frames reuse one): its
// tessellation for `camera` (by the CPU, or by `context`'s GPU tessellator), with its stats
// and warnings in `out`. `keepHidden`: no patch culled (a tessellation later frames reuse).
patches::PatchMesh tessellatePatchSet(const patches::PatchSet& set, const MethodChoice& choice,
                                      const JobLimits& limits, const Camera& camera,
                                      RenderContext* context, const CancelToken& cancel,
                                      Approximated& out, bool keepHidden = false);
// A patch tessellation as the method's mesh and, with outputs.patches, the patch image's mesh.
void drawPatchMesh(patches::PatchMesh tessellation, const patches::PatchSet& set,
                   const MethodChoice& choice, Approximated& out);

// An approximation and its raster passes.
struct MethodDrawing {
  Approximated approx;
  ImageSet images;  // every pass the metrics need when measured, else the requested ones
  double rasterMs = 0;
};

// `measured`: rasterise color, mask, depth, normal and the mask at `supersample` times the
// size, whatever the outputs say (measureDrawing needs them).
MethodDrawing drawMethod(const MethodChoice& choice, const JobLimits& limits,
                         const subdiv::LimitSurface& surface, const Camera& camera,
                         RenderContext& context, bool measured, int supersample,
                         const CancelToken& cancel);

// The raster passes of an approximation made already (drawMethod's second half).
MethodDrawing rasterizeApproximation(Approximated approx, const MethodChoice& choice,
                                     const subdiv::LimitSurface& surface, const Camera& camera,
                                     RenderContext& context, bool measured, int supersample,
                                     const CancelToken& cancel);

// The passes a reference must cast for a camera: all of them, and the supersampled mask when
// something is measured against it.
PassSelection referencePasses(bool measured, int supersample);
// Where the reference casts its colour rays so that its picture is anti-aliased like the
// rasteriser's (ReferenceOptions::colorSamples): the rasteriser's sample positions, or none.
std::vector<std::array<float, 2>> colorSamples(RenderContext& context, const Outputs& outputs);
// A warning when the device draws fewer samples per pixel than outputs.antialias asks for.
std::optional<std::string> antialiasWarning(RenderContext& context, const Outputs& outputs);

// Every metric of `drawing` (measured) against `reference` (hinted with its mask, alone or
// merged with others: oracle::maskBlocks), and the geometric error against the limit surface.
// With `diff`, the heat map goes into drawing.images and its scale into the colour metrics.
// `timings` (optional) gets the time of each group of metrics.
metrics::Metrics measureDrawing(MethodDrawing& drawing, const oracle::ReferenceResult& reference,
                                const subdiv::LimitSurface& surface, const Camera& camera,
                                int supersample, bool diff, const CancelToken& cancel,
                                metrics::MetricsTimings* timings = nullptr);

// The checks of one method's params and shading against `limits` (InputError naming the
// parameter, e.g. "params.level").
void checkMethod(const MethodChoice& choice, const JobLimits& limits);

}  // namespace limn::render::pipeline
