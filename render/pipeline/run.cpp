#include <chrono>
#include <string>

#include "render/core/error.h"
#include "render/oracle/reference.h"
#include "render/pipeline/render_job.h"
#include "render/raster/rasterizer.h"
#include "render/subdiv/limit_surface.h"
#include "render/tessellate/tessellate.h"

namespace limn::render::pipeline {

namespace {

class Stopwatch {
 public:
  double lapMs() {
    auto now = std::chrono::steady_clock::now();
    double ms = std::chrono::duration<double, std::milli>(now - last_).count();
    last_ = now;
    return ms;
  }

 private:
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

[[noreturn]] void badParameter(const std::string& name, const std::string& message) {
  throw InputError(InputError::Kind::InvalidParameter, name, name + " " + message);
}

void checkJob(const RenderJob& job, const JobLimits& limits) {
  const MethodParams& p = job.params;
  if (p.level < 0 || p.level > limits.maxLevel) {
    badParameter("params.level", "must be in 0.." + std::to_string(limits.maxLevel));
  }
  if (!(p.dicingRate >= limits.minDicingRate)) {
    badParameter("params.dicingRate", "must be >= " + std::to_string(limits.minDicingRate));
  }
  if (p.metricSupersample < 1 || p.metricSupersample > limits.maxSupersample) {
    badParameter("params.metricSupersample",
                 "must be in 1.." + std::to_string(limits.maxSupersample));
  }
  for (const std::optional<int>& side : {job.camera.width, job.camera.height}) {
    if (side && (*side < 1 || *side > limits.maxImageSide)) {
      throw InputError(InputError::Kind::LimitExceeded, "maxImageSide",
                       "image side " + std::to_string(*side) + " exceeds limit maxImageSide " +
                           std::to_string(limits.maxImageSide));
    }
  }
}

tessellate::TriangleMesh approximate(const RenderJob& job, const JobLimits& limits,
                                     const subdiv::LimitSurface& surface, const Camera& camera,
                                     const CancelToken& cancel) {
  switch (job.method) {
    case Method::Coarse: return tessellate::tessellateCoarse(surface);
    case Method::Uniform:
      return tessellate::tessellateUniform(surface, job.params.level, limits.maxTriangles);
    case Method::Adaptive: {
      tessellate::AdaptiveOptions options;
      options.dicingRate = job.params.dicingRate;
      options.maxTriangles = limits.maxTriangles;
      return tessellate::tessellateAdaptive(surface, camera, options, cancel);
    }
    case Method::Limit: break;
  }
  return {};
}

// Keeps only the passes the client asked for; the wireframe of the reference is its colour
// (the exact surface has no edges to draw).
ImageSet selectOutputs(ImageSet images, const Outputs& outputs, bool isReference) {
  ImageSet selected;
  auto keep = [&](bool wanted, const char* name) {
    if (!wanted) return;
    auto it = images.passes.find(name);
    if (it != images.passes.end()) selected.passes[name] = std::move(it->second);
  };
  if (isReference && outputs.wireframe && images.passes.count(pass::kColor)) {
    selected.passes[pass::kWireframe] = images.passes[pass::kColor];
  }
  keep(outputs.color, pass::kColor);
  keep(outputs.mask, pass::kMask);
  keep(outputs.depth, pass::kDepth);
  keep(outputs.normal, pass::kNormal);
  if (!isReference) keep(outputs.wireframe, pass::kWireframe);
  return selected;
}

}  // namespace

const char* methodName(Method method) {
  switch (method) {
    case Method::Coarse: return "coarse";
    case Method::Uniform: return "uniform";
    case Method::Adaptive: return "adaptive";
    case Method::Limit: return "limit";
  }
  return "?";
}

RenderResult run(const RenderJob& job, const JobLimits& limits, RenderContext& context,
                 const CancelToken& cancel) {
  Stopwatch clock, total;
  checkJob(job, limits);
  mesh::validateMesh(job.mesh, limits.mesh);
  cancel.check();

  const subdiv::LimitSurface surface(job.mesh);
  Camera camera = resolveCamera(job.camera, surface.bounds());
  RenderResult result{.images = {}, .referenceImages = {}, .metrics = {}, .stats = {},
                      .timings = {}, .warnings = {}, .camera = camera};
  result.timings.surfaceMs = clock.lapMs();
  result.stats.controlVertices = job.mesh.vertexCount();
  result.stats.controlFaces = job.mesh.faceCount();
  cancel.check();

  const int S = job.params.metricSupersample;
  const bool measure = job.reference && job.method != Method::Limit;
  const bool needReference = job.reference || job.method == Method::Limit;

  // The approximation and its raster passes (all of them when metrics need them).
  std::optional<tessellate::TriangleMesh> approx;
  if (job.method != Method::Limit) {
    approx = approximate(job, limits, surface, camera, cancel);
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
    result.images = context.rasterizer->render(*approx, camera, passes, job.shading);
    result.timings.rasterMs = clock.lapMs();
    cancel.check();
  }

  // The exact reference and, for Catmull-Clark, its independent cross-check.
  if (needReference) {
    PassSelection passes{.color = true, .mask = true, .depth = true, .normal = true,
                         .supersample = measure ? S : 0};
    oracle::ReferenceResult reference = oracle::renderReference(surface, camera, passes, cancel);
    result.stats.referenceTriangles = reference.stats.triangles;
    result.warnings.insert(result.warnings.end(), reference.warnings.begin(),
                           reference.warnings.end());
    if (measure && job.mesh.scheme == mesh::Scheme::CatmullClark) {
      std::string whyNot;
      std::optional<Image> embreeMask =
          oracle::embreeSubdivisionMask(surface, camera.scaled(S), cancel, &whyNot);
      if (embreeMask) {
        metrics::SilhouetteMetrics agreement =
            metrics::compareSilhouettes(*embreeMask, reference.images.supersampledMask, S);
        result.stats.referenceCrossCheckPx = agreement.hausdorffPx;
        result.stats.referenceCrossCheckMeanPx = agreement.meanPx;
        if (agreement.hausdorffPx > 1.0) {
          result.warnings.push_back(
              "the two reference paths disagree: Embree's subdivision geometry is " +
              std::to_string(agreement.hausdorffPx) + " px from the tessellated reference");
        }
      } else {
        result.warnings.push_back("reference cross-check skipped: " + whyNot);
      }
    }
    result.timings.referenceMs = clock.lapMs();
    cancel.check();

    if (measure) {
      const ImageSet& approxImages = result.images;
      const ImageSet& refImages = reference.images;
      result.metrics.silhouette = metrics::compareSilhouettes(
          approxImages.supersampledMask, refImages.supersampledMask, S);
      result.metrics.image = metrics::compareColor(approxImages, refImages);
      result.metrics.depth =
          metrics::compareDepth(approxImages, refImages, surface.bounds().diagonal());
      result.metrics.normal = metrics::compareNormals(approxImages, refImages);
    }
    if (job.method == Method::Limit) {
      result.images = selectOutputs(reference.images, job.outputs, true);
      result.stats.triangles = reference.stats.triangles;
    }
    if (job.reference) result.referenceImages = selectOutputs(std::move(reference.images), job.outputs, true);
  }
  if (approx && job.reference) result.metrics.geometry = metrics::measureGeometry(*approx, surface);
  result.timings.metricsMs = clock.lapMs();

  if (job.method != Method::Limit) result.images = selectOutputs(std::move(result.images), job.outputs, false);
  result.timings.totalMs = total.lapMs();
  return result;
}

}  // namespace limn::render::pipeline
