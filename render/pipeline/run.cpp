#include <chrono>
#include <cmath>
#include <string>

#include "render/core/error.h"
#include "render/oracle/reference.h"
#include "render/pipeline/approximation.h"
#include "render/pipeline/drawing.h"
#include "render/pipeline/job_checks.h"
#include "render/pipeline/measure.h"
#include "render/pipeline/reference_beside.h"
#include "render/pipeline/render_job.h"
#include "render/subdiv/limit_surface.h"

namespace limn::render::pipeline {

namespace {

void checkJob(const RenderJob& job, const JobLimits& limits) {
  checkMethod({job.mesh, job.method, job.params, job.shading, job.outputs}, limits);
  checkDisplacement(job.displacement, job.method, "method");
  checkImageSides(job.camera, limits);
  if (job.reference && job.method != Method::Limit) {
    checkSupersampledMasks(job.camera, job.params.metricSupersample, limits);
  }
  if (job.outputs.diff && (!job.reference || job.method == Method::Limit)) {
    badParameter("outputs",
                 "\"diff\" compares a method's colour with the reference: it needs "
                 "\"reference\": true and a method other than \"limit\"");
  }
}

// The independent check: Embree's own subdivision geometry against the reference's mask and
// outline; the agreement goes into stats, a disagreement over a pixel or the reason it could not
// run (Loop, bilinear, rules Embree does not share) into the warnings.
void crossCheckReference(const subdiv::LimitSurface& surface, const Camera& camera, int S,
                         const oracle::ReferenceResult& reference, const CancelToken& cancel,
                         RenderResult& result) {
  std::string whyNot;
  metrics::Outline embreeOutline;
  std::optional<Mask> embreeMask =
      oracle::embreeSubdivisionMask(surface, camera.scaled(S), cancel, &whyNot, S, &embreeOutline);
  if (!embreeMask) {
    result.warnings.push_back("reference cross-check skipped: " + whyNot);
    return;
  }
  metrics::SilhouetteMetrics agreement =
      metrics::compareSilhouettes(*embreeMask, reference.images.supersampledMask, S);
  result.stats.referenceCrossCheckPx = agreement.hausdorffPx;
  result.stats.referenceCrossCheckMeanPx = agreement.meanPx;
  metrics::OutlineDistances outline = metrics::compareOutlines(
      embreeOutline, reference.outline, std::hypot(camera.width(), camera.height()));
  result.stats.referenceCrossCheckOutlinePx = outline.hausdorffPx;
  result.stats.referenceCrossCheckOutlineMeanPx = outline.meanPx;
  if (agreement.hausdorffPx > 1.0) {
    result.warnings.push_back(
        "the two reference paths disagree: Embree's subdivision geometry is " +
        std::to_string(agreement.hausdorffPx) + " px from the tessellated reference");
  }
}

}  // namespace

Approximation approximate(const RenderJob& job, const JobLimits& limits,
                          const CancelToken& cancel) {
  Stopwatch clock, total;
  if (job.method == Method::Limit) {
    badParameter("method",
                 "\"limit\" is the ray-cast reference: it has no mesh; choose a method that "
                 "tessellates (coarse, uniform, adaptive, silhouette)");
  }
  checkJob(job, limits);
  mesh::validateMesh(job.mesh, limits.mesh);
  cancel.check();
  const subdiv::LimitSurface surface(job.mesh, cancel, job.displacement);
  if (evaluatesLimitSurface(job.method, false)) surface.prepare(cancel);
  Approximation out{.mesh = {},
                    .camera = resolveCamera(job.camera, surface.bounds()),
                    .stats = {},
                    .timings = {},
                    .warnings = {}};
  out.timings.surfaceMs = clock.lapMs();
  out.stats.controlVertices = job.mesh.vertexCount();
  out.stats.controlFaces = job.mesh.faceCount();
  cancel.check();
  const Outputs none{.color = false};  // a mesh to hand out: no overlays
  Approximated made = approximateMethod({job.mesh, job.method, job.params, job.shading, none},
                                        limits, surface, out.camera, nullptr, cancel);
  out.mesh = std::move(made.mesh);
  out.stats.triangles = made.stats.triangles;
  out.stats.vertices = made.stats.vertices;
  out.stats.silhouette = made.stats.silhouette;
  out.stats.presubdivided = made.stats.presubdivided;
  out.stats.patches = made.stats.patches;
  out.stats.patchTable = made.stats.patchTable;
  out.warnings = std::move(made.warnings);
  out.timings.approxMs = clock.lapMs();
  out.timings.totalMs = total.lapMs();
  return out;
}

const char* methodName(Method method) {
  switch (method) {
    case Method::Coarse:
      return "coarse";
    case Method::Uniform:
      return "uniform";
    case Method::Adaptive:
      return "adaptive";
    case Method::Limit:
      return "limit";
    case Method::Silhouette:
      return "silhouette";
    case Method::Patches:
      return "patches";
  }
  return "?";
}

RenderResult run(const RenderJob& job, const JobLimits& limits, RenderContext& context,
                 const CancelToken& cancel) {
  Stopwatch clock, total;
  checkJob(job, limits);
  mesh::validateMesh(job.mesh, limits.mesh);
  cancel.check();
  if (!job.frames.empty()) return runFrames(job, limits, context, cancel);

  const subdiv::LimitSurface surface(job.mesh, cancel, job.displacement);
  if (evaluatesLimitSurface(job.method, job.reference)) surface.prepare(cancel);
  Camera camera = resolveCamera(job.camera, surface.bounds());
  RenderResult result{.images = {},
                      .referenceImages = {},
                      .metrics = {},
                      .stats = {},
                      .timings = {},
                      .warnings = {},
                      .camera = camera,
                      .frames = {}};
  result.timings.surfaceMs = clock.lapMs();
  result.stats.controlVertices = job.mesh.vertexCount();
  result.stats.controlFaces = job.mesh.faceCount();
  cancel.check();

  const int S = job.params.metricSupersample;
  const bool measure = job.reference && job.method != Method::Limit;
  const bool referenced = job.reference || job.method == Method::Limit;
  const PassSelection referencePassesAsked = referencePasses(measure, S);
  oracle::ReferenceOptions options{
      .locateOutline = measure,
      .cache = context.referenceCache,
      .triangleBudget = static_cast<double>(limits.maxReferenceTriangles)};
  // Asks OpenGL (so on this thread), and only when a reference is made: a plain render's time.
  if (referenced) options.colorSamples = colorSamples(context, job.outputs);

  // The approximation, then its raster passes (all of them when metrics need them).
  const MethodChoice choice{job.mesh, job.method, job.params, job.shading, job.outputs};
  std::optional<Approximated> made;
  if (job.method != Method::Limit) {
    made = approximateMethod(choice, limits, surface, camera, &context, cancel);
  }

  // The reference's first half needs nothing of the approximation: it runs while the
  // approximation is rasterised (reference_beside.h).
  std::optional<ReferenceBeside> beside;
  if (referenced && made) beside.emplace(surface, camera, referencePassesAsked, cancel, options);

  std::optional<MethodDrawing> drawing;
  if (made) {
    drawing = rasterizeApproximation(std::move(*made), choice, surface, camera, context, measure, S,
                                     cancel);
    const Approximated& approx = drawing->approx;
    result.stats.triangles = approx.stats.triangles;
    result.stats.vertices = approx.stats.vertices;
    result.stats.silhouette = approx.stats.silhouette;
    result.stats.presubdivided = approx.stats.presubdivided;
    result.stats.patches = approx.stats.patches;
    result.stats.patchTable = approx.stats.patchTable;
    result.warnings.insert(result.warnings.end(), approx.warnings.begin(), approx.warnings.end());
    if (auto fewer = antialiasWarning(context, job.outputs)) result.warnings.push_back(*fewer);
    result.timings.approxMs = approx.approxMs;
    result.timings.rasterMs = drawing->rasterMs;
    clock.lapMs();
  }

  // The exact reference and, for Catmull-Clark, its independent cross-check.
  if (referenced) {
    options.maskHint = drawing ? &drawing->images.supersampledMask : nullptr;
    Stopwatch own;
    oracle::ReferenceResult reference =
        beside ? beside->finish(options)
               : oracle::renderReference(surface, camera, referencePassesAsked, cancel, options);
    const double referenceMs = beside ? beside->ownMs() : own.lapMs();
    result.stats.referenceTriangles = reference.stats.triangles;
    result.warnings.insert(result.warnings.end(), reference.warnings.begin(),
                           reference.warnings.end());
    result.timings.reference = reference.stats;
    if (measure && job.params.referenceCrossCheck) {
      Stopwatch crossCheck;
      crossCheckReference(surface, camera, S, reference, cancel, result);
      result.timings.crossCheckMs = crossCheck.lapMs();
    }
    clock.lapMs();
    result.timings.referenceMs = referenceMs + result.timings.crossCheckMs;
    cancel.check();

    if (measure) {
      metrics::MetricsTimings stages;
      result.metrics = measureDrawing(*drawing, reference, surface, camera, S, job.outputs.diff,
                                      cancel, &stages);
      result.timings.metricsStages = stages;
      if (auto note = referenceAccuracyNote(result.metrics, reference.stats)) {
        result.warnings.push_back(*note);
      }
    }
    if (job.method == Method::Limit) {
      result.images = selectOutputs(reference.images, job.outputs, true);
      result.stats.triangles = reference.stats.triangles;
    }
    if (job.reference)
      result.referenceImages = selectOutputs(std::move(reference.images), job.outputs, true);
  }
  result.timings.metricsMs = clock.lapMs();

  if (drawing) result.images = selectOutputs(std::move(drawing->images), job.outputs, false);
  result.timings.totalMs = total.lapMs();
  return result;
}

}  // namespace limn::render::pipeline
