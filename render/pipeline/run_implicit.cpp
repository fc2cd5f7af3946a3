#include <cmath>
#include <cstdio>
#include <string>

#include "render/core/error.h"
#include "render/oracle/implicit_reference.h"
#include "render/pipeline/drawing.h"
#include "render/pipeline/implicit_job.h"
#include "render/pipeline/job_checks.h"
#include "render/pipeline/measure.h"
#include "render/raster/rasterizer.h"

namespace limn::render::pipeline {

namespace {

[[noreturn]] void overLimit(const char* limit, const std::string& message) {
  throw InputError(InputError::Kind::LimitExceeded, limit, message);
}

void checkImplicitJob(const ImplicitJob& job, const JobLimits& limits) {
  const auto& primitives = job.field.primitives;
  if (primitives.size() > static_cast<size_t>(limits.maxPrimitives)) {
    overLimit("maxPrimitives", "the field has " + std::to_string(primitives.size()) +
                                   " primitives; limits.maxPrimitives is " +
                                   std::to_string(limits.maxPrimitives));
  }
  for (size_t i = 0; i < primitives.size(); ++i) {
    if (primitives[i].expression.size() > limits.maxExpressionLength) {
      overLimit("maxExpressionLength", "field.primitives[" + std::to_string(i) +
                                           "].expression has " +
                                           std::to_string(primitives[i].expression.size()) +
                                           " characters; limits.maxExpressionLength is " +
                                           std::to_string(limits.maxExpressionLength));
    }
  }
  if (job.polygonizer.resolution > limits.maxResolution) {
    overLimit("maxResolution",
              "polygonizer.resolution " + std::to_string(job.polygonizer.resolution) +
                  " is over limits.maxResolution (" + std::to_string(limits.maxResolution) + ")");
  }
  if (job.shading == Shading::NormalMap) {
    badParameter("shading",
                 "\"normal-map\" is for subdivision surfaces; an isosurface mesh "
                 "carries the field's normals per vertex (\"smooth\") or \"flat\"");
  }
  if (job.metricSupersample < 1 || job.metricSupersample > limits.maxSupersample) {
    badParameter("params.metricSupersample",
                 "must be in 1.." + std::to_string(limits.maxSupersample));
  }
  checkImageSides(job.camera, limits);
  checkAntialias(job.outputs);
  if (job.reference) checkSupersampledMasks(job.camera, job.metricSupersample, limits);
  if (job.outputs.diff && !job.reference) {
    badParameter("outputs", "\"diff\" compares with the reference: it needs \"reference\": true");
  }
}

implicit::PolygonizerOptions withLimits(implicit::PolygonizerOptions options,
                                        const JobLimits& limits) {
  options.maxTriangles = std::min(options.maxTriangles, limits.maxTriangles);
  return options;
}

Stats::Implicit implicitStats(const ImplicitJob& job, const implicit::Polygonization& p) {
  return {.primitives = job.field.primitives.size(),
          .method = job.polygonizer.method,
          .polygonizer = p.stats,
          .closure = implicit::checkClosure(p.mesh)};
}

Bounds surfaceBounds(const tessellate::TriangleMesh& mesh, const implicit::Field& field) {
  Bounds bounds;
  for (const Vec3f& p : mesh.positions) bounds.extend(p.toDouble());
  return bounds.empty() ? field.bounds() : bounds;
}

}  // namespace

namespace {

// A field whose primitives all stay below the iso value bounds nothing: there is no surface to
// polygonise, draw or measure (a field that bounds a region is drawn even when the polygoniser
// finds nothing in it: that miss is what the metrics are for).
void checkHasSurface(const implicit::Field& field, double iso) {
  const double diagonal = field.bounds().diagonal();
  if (!(diagonal > 0) || !std::isfinite(diagonal)) {
    char value[32];
    std::snprintf(value, sizeof value, "%g", iso);
    throw InputError(InputError::Kind::EmptySurface, "field.iso",
                     std::string("the field has no surface at iso ") + value +
                         ": no primitive reaches that value anywhere");
  }
}

}  // namespace

ImplicitMesh polygonizeImplicit(const ImplicitJob& job, const JobLimits& limits,
                                const CancelToken& cancel) {
  Stopwatch clock;
  checkImplicitJob(job, limits);
  const implicit::Field field(job.field);
  checkHasSurface(field, job.field.iso);
  ImplicitMesh out;
  out.timings.surfaceMs = clock.lapMs();
  implicit::Polygonization p =
      implicit::polygonize(field, withLimits(job.polygonizer, limits), cancel);
  out.stats.implicit = implicitStats(job, p);
  out.mesh = std::move(p.mesh);
  out.stats.triangles = out.mesh.triangleCount();
  out.stats.vertices = out.mesh.vertexCount();
  out.timings.approxMs = clock.lapMs();
  out.timings.totalMs = out.timings.surfaceMs + out.timings.approxMs;
  return out;
}

RenderResult runImplicit(const ImplicitJob& job, const JobLimits& limits, RenderContext& context,
                         const CancelToken& cancel) {
  Stopwatch clock, total;
  checkImplicitJob(job, limits);
  const implicit::Field field(job.field);
  checkHasSurface(field, job.field.iso);
  const double surfaceMs = clock.lapMs();
  cancel.check();

  implicit::Polygonization p =
      implicit::polygonize(field, withLimits(job.polygonizer, limits), cancel);
  // The default view frames the surface the polygoniser found, not the primitives' supports
  // (a soft object's support is twice the radius of its surface).
  const Camera camera = resolveCamera(job.camera, surfaceBounds(p.mesh, field));
  RenderResult result{.images = {},
                      .referenceImages = {},
                      .metrics = {},
                      .stats = {},
                      .timings = {},
                      .warnings = {},
                      .camera = camera,
                      .frames = {}};
  result.timings.surfaceMs = surfaceMs;
  result.stats.implicit = implicitStats(job, p);
  const tessellate::TriangleMesh& approx = p.mesh;
  result.stats.triangles = approx.triangleCount();
  result.stats.vertices = approx.vertexCount();
  if (!result.stats.implicit->closure.closed()) {
    result.warnings.push_back(
        "the mesh is not closed: " + std::to_string(result.stats.implicit->closure.boundaryEdges) +
        " boundary edges (a positive expression's bounds cut the surface?)");
  }
  result.timings.approxMs = clock.lapMs();
  cancel.check();

  const int S = job.metricSupersample;
  PassSelection passes{.color = job.outputs.color || job.reference,
                       .mask = job.outputs.mask || job.reference,
                       .depth = job.outputs.depth || job.reference,
                       .normal = job.outputs.normal || job.reference,
                       .wireframe = job.outputs.wireframe,
                       .supersample = job.reference ? S : 0,
                       .antialias = job.outputs.antialias};
  if (context.rasterizer == nullptr) throw std::runtime_error("no rasterizer in this context");
  result.images = context.rasterizer->render(approx, camera, passes, job.shading, {}, cancel);
  result.timings.rasterMs = clock.lapMs();
  if (auto fewer = antialiasWarning(context, job.outputs)) result.warnings.push_back(*fewer);
  cancel.check();

  if (job.reference) {
    PassSelection referencePasses{
        .color = true, .mask = true, .depth = true, .normal = true, .supersample = S};
    oracle::ReferenceOptions options{
        .maskHint = &result.images.supersampledMask, .locateOutline = true, .cache = nullptr};
    options.colorSamples = colorSamples(context, job.outputs);
    oracle::ReferenceResult reference =
        oracle::renderImplicitReference(field, camera, referencePasses, cancel, options);
    result.warnings.insert(result.warnings.end(), reference.warnings.begin(),
                           reference.warnings.end());
    result.timings.reference = reference.stats;
    result.timings.referenceMs = clock.lapMs();
    cancel.check();
    measureAgainstReference(approx, camera, S, reference, field.bounds().diagonal(),
                            job.outputs.diff, cancel, result);
    result.referenceImages = selectOutputs(std::move(reference.images), job.outputs, true);
  }
  const implicit::ImplicitGeometryError error =
      implicit::measureImplicitGeometry(approx, field, cancel);
  result.metrics.geometry = metrics::GeometryMetrics{.maxDist = error.maxDist,
                                                     .meanDist = error.meanDist,
                                                     .relMaxDist = error.relMaxDist,
                                                     .relMeanDist = error.relMeanDist};
  result.timings.metricsMs = clock.lapMs();
  result.images = selectOutputs(std::move(result.images), job.outputs, false);
  result.timings.totalMs = total.lapMs();
  return result;
}

}  // namespace limn::render::pipeline
