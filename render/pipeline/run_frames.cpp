// runFrames(): one request, many animation frames of one topology (method patches). The
// topology, adaptive refinement, patch table and point stencils are built once from the
// request's mesh; each frame only re-evaluates the points (PatchSet::setControlPoints). The
// first frame is tessellated with no patch culled (a later frame may turn it into view); later
// frames re-evaluate that tessellation's vertices where they were made
// (patches::reevaluatePatchMesh) unless params.retessellateFrames asks for each frame's own
// factors, or the GPU tessellator dices each frame. Every frame is rasterised for the same
// camera, which frames the request's mesh.
#include <optional>
#include <string>

#include "render/core/error.h"
#include "render/pipeline/drawing.h"
#include "render/pipeline/job_checks.h"
#include "render/pipeline/measure.h"
#include "render/tessellate/cage_overlay.h"

namespace limn::render::pipeline {

namespace {

void checkFrames(const RenderJob& job, const JobLimits& limits) {
  if (job.method != Method::Patches) {
    badParameter("frames", "frames are drawn by method \"patches\" (its patch table is reused)");
  }
  if (job.reference) {
    badParameter("reference",
                 "frames are drawn without the reference; measure a frame on its own (its "
                 "points as the mesh) with \"reference\": true");
  }
  if (job.frames.size() > limits.maxFrames) {
    throw InputError(InputError::Kind::LimitExceeded, "maxFrames",
                     "frames: " + std::to_string(job.frames.size()) + " exceed limit maxFrames (" +
                         std::to_string(limits.maxFrames) + ")");
  }
  const size_t passes = static_cast<size_t>(job.outputs.count());
  const size_t pixels = job.frames.size() * passes *
                        static_cast<size_t>(job.camera.width.value_or(kDefaultImageSide)) *
                        static_cast<size_t>(job.camera.height.value_or(kDefaultImageSide));
  if (pixels > limits.maxFramePixels) {
    throw InputError(InputError::Kind::LimitExceeded, "maxFramePixels",
                     "frames: " + std::to_string(pixels) +
                         " image pixels (frames x width x height x outputs) exceed limit "
                         "maxFramePixels (" +
                         std::to_string(limits.maxFramePixels) + ")");
  }
  for (size_t f = 0; f < job.frames.size(); ++f) {
    if (job.frames[f].size() != job.mesh.points.size()) {
      badParameter("frames[" + std::to_string(f) + "]",
                   "frames[" + std::to_string(f) + "] has " + std::to_string(job.frames[f].size()) +
                       " points; the mesh has " + std::to_string(job.mesh.points.size()));
    }
  }
}

}  // namespace

RenderResult runFrames(const RenderJob& job, const JobLimits& limits, RenderContext& context,
                       const CancelToken& cancel) {
  Stopwatch clock, total;
  checkFrames(job, limits);
  const subdiv::LimitSurface surface(job.mesh, cancel, job.displacement);
  if (evaluatesLimitSurface(job.method, job.reference)) surface.prepare(cancel);
  RenderResult result{.images = {},
                      .referenceImages = {},
                      .metrics = {},
                      .stats = {},
                      .timings = {},
                      .warnings = {},
                      .camera = resolveCamera(job.camera, surface.bounds()),
                      .frames = {}};
  result.stats.controlVertices = job.mesh.vertexCount();
  result.stats.controlFaces = job.mesh.faceCount();
  result.timings.surfaceMs = clock.lapMs();

  patches::PatchSet set(job.mesh, job.params.isolation, cancel, job.displacement);
  Outputs outputs = job.outputs;
  outputs.cage = false;  // drawn below with each frame's own points
  mesh::ControlMesh frameMesh = job.mesh;
  const bool reuse =
      !job.params.retessellateFrames && job.params.tessellator == PatchTessellator::Cpu;
  std::optional<patches::PatchMesh> first;  // the first frame's tessellation, when reused
  for (size_t f = 0; f < job.frames.size(); ++f) {
    cancel.check();
    Stopwatch frameClock;
    set.setControlPoints(job.frames[f]);
    frameMesh.points = job.frames[f];
    const MethodChoice choice{frameMesh, job.method, job.params, job.shading, outputs};
    Approximated approx;
    if (first) {
      patches::reevaluatePatchMesh(set, *first, cancel);
      drawPatchMesh(*first, set, choice, approx);
    } else {
      patches::PatchMesh mesh = tessellatePatchSet(set, choice, limits, result.camera, &context,
                                                   cancel, approx, /*keepHidden=*/reuse);
      if (reuse) first = mesh;
      drawPatchMesh(std::move(mesh), set, choice, approx);
    }
    if (job.outputs.cage)
      approx.overlays.push_back(tessellate::cageOverlay(frameMesh, pass::kCage));
    approx.stats.triangles = approx.mesh.triangleCount();
    approx.stats.vertices = approx.mesh.vertexCount();
    const double approxMs = frameClock.lapMs();
    if (f == 0) {
      result.stats.triangles = approx.stats.triangles;
      result.stats.vertices = approx.stats.vertices;
      result.stats.patches = approx.stats.patches;
      result.stats.patchTable = approx.stats.patchTable;
    }
    result.warnings.insert(result.warnings.end(), approx.warnings.begin(), approx.warnings.end());
    MethodDrawing drawing = rasterizeApproximation(std::move(approx), choice, surface,
                                                   result.camera, context, false, 0, cancel);
    result.frames.push_back({.images = selectOutputs(std::move(drawing.images), job.outputs, false),
                             .triangles = drawing.approx.stats.triangles,
                             .approxMs = approxMs,
                             .rasterMs = drawing.rasterMs});
    result.timings.approxMs += approxMs;
    result.timings.rasterMs += drawing.rasterMs;
  }
  result.timings.totalMs = total.lapMs();
  return result;
}

}  // namespace limn::render::pipeline
