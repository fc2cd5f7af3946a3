#include "render/pipeline/compare.h"

#include <functional>
#include <string>

#include "render/pipeline/drawing.h"
#include "render/pipeline/job_checks.h"
#include "render/pipeline/measure.h"
#include "render/pipeline/reference_beside.h"
#include "render/subdiv/limit_surface.h"

namespace limn::render::pipeline {

namespace {

// Runs `check`, re-throwing an InputError with its subject placed under `prefix`
// ("params.level" -> "methods[2].params.level"); a limit keeps its key as the subject (clients
// read the limit's name there) and gets the prefix in its message instead.
void within(const std::string& prefix, const std::function<void()>& check) {
  try {
    check();
  } catch (const InputError& e) {
    if (e.kind() == InputError::Kind::LimitExceeded) {
      throw InputError(e.kind(), e.subject(), prefix + ": " + e.what());
    }
    throw InputError(e.kind(), prefix + "." + e.subject(), prefix + "." + e.what());
  }
}

MethodChoice choiceOf(const CompareJob& job, size_t m) {
  const CompareMethod& method = job.methods[m];
  return {job.mesh, method.method, method.params, method.shading, job.outputs};
}

// Everything the request could get wrong, before any work.
void checkCompare(const CompareJob& job, const JobLimits& limits) {
  if (job.methods.empty()) badParameter("methods", "must list at least one method");
  if (job.cameras.empty()) badParameter("cameras", "must list at least one camera");
  const size_t rows = job.methods.size() * job.cameras.size();
  if (rows > limits.maxCompareRows) {
    throw InputError(InputError::Kind::LimitExceeded, "maxCompareRows",
                     std::to_string(job.methods.size()) + " methods x " +
                         std::to_string(job.cameras.size()) + " cameras = " + std::to_string(rows) +
                         " rows: exceeds limit maxCompareRows (" +
                         std::to_string(limits.maxCompareRows) + ")");
  }
  if (job.metricSupersample < 1 || job.metricSupersample > limits.maxSupersample) {
    badParameter("metricSupersample", "must be in 1.." + std::to_string(limits.maxSupersample));
  }
  for (size_t m = 0; m < job.methods.size(); ++m) {
    const std::string prefix = "methods[" + std::to_string(m) + "]";
    if (job.methods[m].method == Method::Limit) {
      badParameter(prefix + ".method",
                   "\"limit\" is the reference every row is measured against; list the methods "
                   "to compare with it");
    }
    within(prefix, [&] { checkMethod(choiceOf(job, m), limits); });
    checkDisplacement(job.displacement, job.methods[m].method, prefix + ".method");
  }
  for (size_t c = 0; c < job.cameras.size(); ++c) {
    within("cameras[" + std::to_string(c) + "]", [&] {
      checkImageSides(job.cameras[c], limits);
      checkSupersampledMasks(job.cameras[c], job.metricSupersample, limits);
    });
  }
}

// A row's stats, warnings, timings and images from its drawing (the drawing's images are moved
// out); the metrics and their time are the caller's.
void fillRow(const CompareJob& job, MethodDrawing& drawing, CompareRow& row) {
  const Approximated& approx = drawing.approx;
  const size_t referenceTriangles = row.stats.referenceTriangles;
  row.stats = approx.stats;
  row.stats.controlVertices = job.mesh.vertexCount();
  row.stats.controlFaces = job.mesh.faceCount();
  row.stats.referenceTriangles = referenceTriangles;
  row.warnings = approx.warnings;
  row.timings.approxMs = approx.approxMs;
  row.timings.rasterMs = drawing.rasterMs;
  row.timings.totalMs = row.timings.approxMs + row.timings.rasterMs + row.timings.metricsMs;
  row.images = selectOutputs(std::move(drawing.images), job.outputs, false);
}

// Every method for camera `c`: drawn first, then one reference hinted with all their masks,
// then each measured against it. A drawing's images are let go as soon as its row is measured.
void compareCamera(const CompareJob& job, size_t c, const JobLimits& limits,
                   const subdiv::LimitSurface& surface, RenderContext& context,
                   const CancelToken& cancel, CompareResult& result) {
  const Camera camera = resolveCamera(job.cameras[c], surface.bounds());
  const int S = job.metricSupersample;
  std::vector<CompareRow> rows(job.methods.size());
  std::vector<std::optional<MethodDrawing>> drawings(job.methods.size());
  std::vector<uint8_t> hint;
  // The reference's first half runs while the methods are drawn (reference_beside.h).
  oracle::ReferenceOptions options;
  std::optional<ReferenceBeside> beside;
  if (job.reference) {
    options = {.locateOutline = true,
               .cache = context.referenceCache,
               .triangleBudget = static_cast<double>(limits.maxReferenceTriangles),
               .colorSamples = colorSamples(context, job.outputs)};
    beside.emplace(surface, camera, referencePasses(true, S), cancel, options);
  }
  for (size_t m = 0; m < job.methods.size(); ++m) {
    rows[m].method = m;
    rows[m].camera = c;
    try {
      drawings[m] =
          drawMethod(choiceOf(job, m), limits, surface, camera, context, job.reference, S, cancel);
      if (job.reference) {
        oracle::mergeMaskBlocks(hint, oracle::maskBlocks(drawings[m]->images.supersampledMask, S));
      }
    } catch (const InputError& e) {
      rows[m].error = RowError{e.kind(), e.subject(), e.what()};
    }
  }

  if (!job.reference) {
    for (size_t m = 0; m < job.methods.size(); ++m) {
      if (drawings[m]) fillRow(job, *drawings[m], rows[m]);
    }
    for (CompareRow& row : rows) result.rows.push_back(std::move(row));
    return;
  }
  CompareReference ref{
      .camera = camera, .stats = {}, .referenceMs = 0, .images = {}, .warnings = {}};
  if (!hint.empty()) {  // else every method failed: nothing to measure
    options.hintBlocks = &hint;
    oracle::ReferenceResult reference = beside->finish(options);
    ref.referenceMs = beside->ownMs();
    ref.stats = reference.stats;
    ref.warnings = reference.warnings;
    if (auto fewer = antialiasWarning(context, job.outputs)) ref.warnings.push_back(*fewer);
    cancel.check();
    for (size_t m = 0; m < job.methods.size(); ++m) {
      if (!drawings[m]) continue;
      CompareRow& row = rows[m];
      Stopwatch metricsClock;
      row.metrics =
          measureDrawing(*drawings[m], reference, surface, camera, S, job.outputs.diff, cancel);
      row.timings.metricsMs = metricsClock.lapMs();
      if (auto note = referenceAccuracyNote(row.metrics, reference.stats)) {
        row.warnings.push_back(*note);
      }
      row.stats.referenceTriangles = reference.stats.triangles;
      fillRow(job, *drawings[m], row);
      drawings[m].reset();
      cancel.check();
    }
    ref.images = selectOutputs(std::move(reference.images), job.outputs, true);
  }
  result.references.push_back(std::move(ref));
  for (CompareRow& row : rows) result.rows.push_back(std::move(row));
}

}  // namespace

CompareResult compare(const CompareJob& job, const JobLimits& limits, RenderContext& context,
                      const CancelToken& cancel) {
  Stopwatch clock, total;
  checkCompare(job, limits);
  mesh::validateMesh(job.mesh, limits.mesh);
  cancel.check();
  const subdiv::LimitSurface surface(job.mesh, cancel, job.displacement);
  surface.prepare(cancel);  // the reference evaluates it
  CompareResult result;
  result.surfaceMs = clock.lapMs();
  result.controlVertices = job.mesh.vertexCount();
  result.controlFaces = job.mesh.faceCount();
  for (size_t c = 0; c < job.cameras.size(); ++c) {
    cancel.check();
    compareCamera(job, c, limits, surface, context, cancel, result);
  }
  result.totalMs = total.lapMs();
  return result;
}

}  // namespace limn::render::pipeline
