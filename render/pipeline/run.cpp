#include <chrono>
#include <cmath>
#include <string>

#include "render/core/error.h"
#include "render/normalmap/mapped_cage.h"
#include "render/normalmap/normal_atlas.h"
#include "render/oracle/reference.h"
#include "render/pipeline/approximation.h"
#include "render/pipeline/job_checks.h"
#include "render/pipeline/measure.h"
#include "render/pipeline/render_job.h"
#include "render/pipeline/silhouette_build.h"
#include "render/raster/rasterizer.h"
#include "render/rules/refine.h"
#include "render/silhouette/contour_overlay.h"
#include "render/subdiv/limit_surface.h"
#include "render/tessellate/cage_overlay.h"
#include "render/tessellate/tessellate.h"

namespace limn::render::pipeline {

namespace {

void checkJob(const RenderJob& job, const JobLimits& limits) {
  const MethodParams& p = job.params;
  if (job.shading == Shading::NormalMap && job.method != Method::Silhouette &&
      job.method != Method::Coarse) {
    badParameter("shading",
                 "\"normal-map\" is available with methods \"silhouette\" and "
                 "\"coarse\" (the others draw limit normals per vertex)");
  }
  if (job.method == Method::Uniform && p.engine != Engine::OpenSubdiv) {
    std::string whyNot = rules::unsupportedReason(
        job.mesh, p.engine == Engine::Masks ? rules::Method::Masks : rules::Method::Factored);
    if (!whyNot.empty()) {
      const char* name = p.engine == Engine::Masks ? "\"masks\"" : "\"factored\"";
      badParameter("params.engine", std::string(name) + " cannot refine this mesh: " + whyNot);
    }
  }
  if (p.level < 0 || p.level > limits.maxLevel) {
    badParameter("params.level", "must be in 0.." + std::to_string(limits.maxLevel));
  }
  if (!(p.dicingRate >= limits.minDicingRate)) {
    badParameter("params.dicingRate", "must be >= " + std::to_string(limits.minDicingRate));
  }
  checkSilhouetteParams(p.searchSteps, p.curveSamples, limits);
  if (p.metricSupersample < 1 || p.metricSupersample > limits.maxSupersample) {
    badParameter("params.metricSupersample",
                 "must be in 1.." + std::to_string(limits.maxSupersample));
  }
  checkImageSides(job.camera, limits);
  if (job.reference && job.method != Method::Limit) {
    checkSupersampledMasks(job.camera, p.metricSupersample, limits);
  }
  if (job.outputs.diff && (!job.reference || job.method == Method::Limit)) {
    badParameter("outputs",
                 "\"diff\" compares a method's colour with the reference: it needs "
                 "\"reference\": true and a method other than \"limit\"");
  }
}

// Normal-map shading: an atlas of the limit normals of `surface`'s faces, sized so the face
// that looks largest gets about half a texel per pixel (bilinear filtering does the rest),
// with at most 64 x 64 texels per face and 4M texels in all.
normalmap::NormalAtlas makeAtlas(const subdiv::LimitSurface& surface, const Camera& camera) {
  constexpr size_t kTexelBudget = size_t{1} << 22;
  constexpr int kMaxSide = 4096, kMaxChartTexels = 64;
  int texels = normalmap::chartTexelsForCamera(surface, camera, 0.5, kTexelBudget, kMaxSide,
                                               kMaxChartTexels);
  return normalmap::NormalAtlas(surface, texels, kMaxSide);
}

// Atlas coordinates for a mesh whose vertices each belong to one face (the silhouette mesh):
// read off the face and (u, v) its triangles record.
void mapNormals(tessellate::TriangleMesh& mesh, const normalmap::NormalAtlas& atlas) {
  mesh.texcoords.assign(mesh.positions.size(), Vec2f{});
  for (size_t t = 0; t < mesh.triangleCount(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const Vec2f& uv = mesh.cornerUVs[3 * t + k];
      mesh.texcoords[mesh.indices[3 * t + k]] =
          atlas.coordinate(mesh.triangleFaces[t], Vec2{uv.x, uv.y});
    }
  }
  mesh.normalMap = atlas.image();
}

tessellate::TriangleMesh approximate(const RenderJob& job, const JobLimits& limits,
                                     const subdiv::LimitSurface& surface, const Camera& camera,
                                     const CancelToken& cancel) {
  switch (job.method) {
    case Method::Coarse:
      if (job.shading == Shading::NormalMap) {
        return normalmap::mappedCage(surface, makeAtlas(surface, camera));
      }
      return tessellate::tessellateCoarse(surface);
    case Method::Uniform: {
      tessellate::UniformOptions options;
      options.level = job.params.level;
      options.engine = job.params.engine == Engine::Masks ? tessellate::UniformEngine::Masks
                       : job.params.engine == Engine::Factored
                           ? tessellate::UniformEngine::Factored
                           : tessellate::UniformEngine::OpenSubdiv;
      options.pushToLimit = job.params.pushToLimit;
      options.maxTriangles = limits.maxTriangles;
      return tessellate::tessellateUniform(surface, options);
    }
    case Method::Adaptive: {
      tessellate::AdaptiveOptions options;
      options.dicingRate = job.params.dicingRate;
      options.maxTriangles = limits.maxTriangles;
      return tessellate::tessellateAdaptive(surface, camera, options, cancel);
    }
    case Method::Limit:
    case Method::Silhouette:
      break;  // see runSilhouette
  }
  return {};
}

// The silhouette method draws a (possibly pre-subdivided) copy of the mesh: same limit
// surface, finer cage. `drawn` keeps that surface alive for the caller.
silhouette::SilhouetteMesh runSilhouette(const RenderJob& job, const JobLimits& limits,
                                         const subdiv::LimitSurface& surface, const Camera& camera,
                                         const CancelToken& cancel,
                                         std::unique_ptr<subdiv::LimitSurface>& drawn,
                                         RenderResult& result) {
  const MethodParams& p = job.params;
  SilhouetteBuild build =
      buildSilhouette(surface, camera, {p.presubdivide, p.searchSteps, p.curveSamples, p.contour},
                      limits.maxTriangles, cancel, result.warnings);
  drawn = std::move(build.presubdivided);
  result.stats.presubdivided = drawn != nullptr;
  result.stats.silhouette = build.built.stats;
  return std::move(build.built);
}

// The independent check: Embree's own subdivision geometry against the reference's mask and
// outline; the agreement goes into stats, a disagreement over a pixel or the reason it could not
// run (Loop, bilinear, rules Embree does not share) into the warnings.
void crossCheckReference(const subdiv::LimitSurface& surface, const Camera& camera, int S,
                         const oracle::ReferenceResult& reference, const CancelToken& cancel,
                         RenderResult& result) {
  std::string whyNot;
  metrics::Outline embreeOutline;
  std::optional<Image> embreeMask =
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
  const subdiv::LimitSurface surface(job.mesh, cancel);
  Approximation out{.mesh = {},
                    .camera = resolveCamera(job.camera, surface.bounds()),
                    .stats = {},
                    .timings = {},
                    .warnings = {}};
  out.timings.surfaceMs = clock.lapMs();
  out.stats.controlVertices = job.mesh.vertexCount();
  out.stats.controlFaces = job.mesh.faceCount();
  cancel.check();
  if (job.method == Method::Silhouette) {
    RenderResult scratch{.images = {},
                         .referenceImages = {},
                         .metrics = {},
                         .stats = {},
                         .timings = {},
                         .warnings = {},
                         .camera = out.camera};
    std::unique_ptr<subdiv::LimitSurface> presubdivided;
    out.mesh = runSilhouette(job, limits, surface, out.camera, cancel, presubdivided, scratch).mesh;
    out.stats.silhouette = scratch.stats.silhouette;
    out.stats.presubdivided = scratch.stats.presubdivided;
    out.warnings = std::move(scratch.warnings);
  } else {
    out.mesh = approximate(job, limits, surface, out.camera, cancel);
  }
  out.stats.triangles = out.mesh.triangleCount();
  out.stats.vertices = out.mesh.vertexCount();
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
  }
  return "?";
}

RenderResult run(const RenderJob& job, const JobLimits& limits, RenderContext& context,
                 const CancelToken& cancel) {
  Stopwatch clock, total;
  checkJob(job, limits);
  mesh::validateMesh(job.mesh, limits.mesh);
  cancel.check();

  const subdiv::LimitSurface surface(job.mesh, cancel);
  Camera camera = resolveCamera(job.camera, surface.bounds());
  RenderResult result{.images = {},
                      .referenceImages = {},
                      .metrics = {},
                      .stats = {},
                      .timings = {},
                      .warnings = {},
                      .camera = camera};
  result.timings.surfaceMs = clock.lapMs();
  result.stats.controlVertices = job.mesh.vertexCount();
  result.stats.controlFaces = job.mesh.faceCount();
  cancel.check();

  const int S = job.params.metricSupersample;
  const bool measure = job.reference && job.method != Method::Limit;
  const bool needReference = job.reference || job.method == Method::Limit;

  // The approximation and its raster passes (all of them when metrics need them).
  std::optional<tessellate::TriangleMesh> approx;
  std::vector<LineOverlay> overlays;
  std::unique_ptr<subdiv::LimitSurface> presubdivided;
  if (job.method == Method::Silhouette) {
    silhouette::SilhouetteMesh built =
        runSilhouette(job, limits, surface, camera, cancel, presubdivided, result);
    if (job.outputs.contours) {
      overlays.push_back(silhouette::contourOverlay(presubdivided ? *presubdivided : surface, built,
                                                    pass::kContours));
    }
    approx = std::move(built.mesh);
    if (job.shading == Shading::NormalMap) {
      mapNormals(*approx, makeAtlas(presubdivided ? *presubdivided : surface, camera));
    }
  } else if (job.method != Method::Limit) {
    approx = approximate(job, limits, surface, camera, cancel);
  }
  if (approx && job.outputs.cage) {
    overlays.push_back(tessellate::cageOverlay(job.mesh, pass::kCage));  // the client's cage
  }
  if (approx) {
    result.stats.triangles = approx->triangleCount();
    result.stats.vertices = approx->vertexCount();
    result.timings.approxMs = clock.lapMs();
    cancel.check();

    PassSelection passes{.color = job.outputs.color || measure,
                         .mask = job.outputs.mask || measure,
                         .depth = job.outputs.depth || measure,
                         .normal = job.outputs.normal || measure,
                         .wireframe = job.outputs.wireframe,
                         .supersample = measure ? S : 0};
    if (context.rasterizer == nullptr) throw std::runtime_error("no rasterizer in this context");
    result.images =
        context.rasterizer->render(*approx, camera, passes, job.shading, overlays, cancel);
    result.timings.rasterMs = clock.lapMs();
    cancel.check();
  }

  // The exact reference and, for Catmull-Clark, its independent cross-check.
  if (needReference) {
    PassSelection passes{
        .color = true, .mask = true, .depth = true, .normal = true, .supersample = measure ? S : 0};
    oracle::ReferenceOptions options{.maskHint = approx ? &result.images.supersampledMask : nullptr,
                                     .locateOutline = measure,
                                     .cache = context.referenceCache};
    oracle::ReferenceResult reference =
        oracle::renderReference(surface, camera, passes, cancel, options);
    result.stats.referenceTriangles = reference.stats.triangles;
    result.warnings.insert(result.warnings.end(), reference.warnings.begin(),
                           reference.warnings.end());
    result.timings.reference = reference.stats;
    if (measure && job.params.referenceCrossCheck) {
      Stopwatch crossCheck;
      crossCheckReference(surface, camera, S, reference, cancel, result);
      result.timings.crossCheckMs = crossCheck.lapMs();
    }
    result.timings.referenceMs = clock.lapMs();
    cancel.check();

    if (measure) {
      measureAgainstReference(*approx, camera, S, reference, surface.bounds().diagonal(),
                              job.outputs.diff, cancel, result);
    }
    if (job.method == Method::Limit) {
      result.images = selectOutputs(reference.images, job.outputs, true);
      result.stats.triangles = reference.stats.triangles;
    }
    if (job.reference)
      result.referenceImages = selectOutputs(std::move(reference.images), job.outputs, true);
  }
  if (approx && job.reference) {
    // Silhouette meshes live on the pre-subdivided copy: the same limit surface, finer faces.
    result.metrics.geometry =
        metrics::measureGeometry(*approx, presubdivided ? *presubdivided : surface);
  }
  result.timings.metricsMs = clock.lapMs();

  if (job.method != Method::Limit)
    result.images = selectOutputs(std::move(result.images), job.outputs, false);
  result.timings.totalMs = total.lapMs();
  return result;
}

}  // namespace limn::render::pipeline
