#include "render/pipeline/contours.h"

#include <chrono>
#include <string>

#include "render/core/error.h"
#include "render/oracle/visibility.h"
#include "render/pipeline/job_checks.h"
#include "render/subdiv/limit_surface.h"

namespace limn::render::pipeline {

namespace {

// The engine checks its limits itself rather than trusting its caller (as run() does).
void checkJob(const ContourJob& job, const JobLimits& limits) {
  const SilhouetteParams& p = job.params;
  checkSilhouetteParams(p.searchSteps, p.curveSamples, limits);
  checkImageSides(job.camera, limits);
}

}  // namespace

ContourResult runContours(const ContourJob& job, const JobLimits& limits,
                          const CancelToken& cancel) {
  Stopwatch clock, total;
  checkJob(job, limits);
  mesh::validateMesh(job.mesh, limits.mesh);
  cancel.check();

  const subdiv::LimitSurface surface(job.mesh, cancel);
  surface.prepare(cancel);
  ContourResult result{.camera = resolveCamera(job.camera, surface.bounds()),
                       .polylines = {},
                       .stats = {},
                       .timings = {},
                       .warnings = {}};
  const Camera& camera = result.camera;
  ContourStats& stats = result.stats;
  stats.controlVertices = job.mesh.vertexCount();
  stats.controlFaces = job.mesh.faceCount();
  result.timings.surfaceMs = clock.lapMs();
  cancel.check();

  SilhouetteBuild build =
      buildSilhouette(surface, camera, job.params, limits.maxTriangles, cancel, result.warnings);
  stats.presubdivided = build.presubdivided != nullptr;
  stats.silhouette = build.built.stats;
  result.timings.contourMs = clock.lapMs();
  cancel.check();

  std::vector<silhouette::ContourPolyline> chained =
      silhouette::chainContourCurves(build.built.curves, camera);
  result.timings.chainMs = clock.lapMs();

  // Visibility against the reference surface, which is the request's own: the pre-subdivided
  // one has the same limit, and the reference is defined on the original. Points off the
  // surface ("pn" samples, unresolved exact ones) widen their rays' offset by how far off.
  const subdiv::LimitSurface& drawn = build.drawn(surface);
  std::vector<oracle::VisibilityPoint> queries;
  for (const silhouette::ContourPolyline& line : chained) {
    for (const silhouette::PolylinePoint& p : line.points) {
      queries.push_back({p.position, p.normal, silhouette::distanceFromSurface(drawn, p)});
    }
  }
  oracle::VisibilityStats seen;
  std::vector<bool> visible = oracle::contourVisibility(surface, camera, queries,
                                                        oracle::VisibilityOptions{}, cancel, &seen);
  result.timings.visibilityMs = clock.lapMs();
  result.timings.referenceTessellateMs = seen.tessellateMs;
  result.timings.bvhMs = seen.bvhMs;
  result.timings.raysMs = seen.traceMs;
  stats.referenceTriangles = seen.triangles;
  stats.raysCast = seen.raysCast;

  size_t next = 0;
  for (silhouette::ContourPolyline& line : chained) {
    ContourLine out;
    out.closed = line.closed;
    out.visible.assign(visible.begin() + next, visible.begin() + next + line.points.size());
    next += line.points.size();
    out.pieces = silhouette::splitPieces(line, out.visible);
    out.points = std::move(line.points);
    for (const silhouette::PolylinePiece& piece : out.pieces) {
      ++(piece.visible ? stats.visiblePieces : stats.hiddenPieces);
    }
    stats.points += out.points.size();
    stats.closedPolylines += out.closed;
    result.polylines.push_back(std::move(out));
  }
  stats.polylines = result.polylines.size();
  stats.hiddenPoints = seen.hidden;
  result.timings.totalMs = total.lapMs();
  return result;
}

}  // namespace limn::render::pipeline
