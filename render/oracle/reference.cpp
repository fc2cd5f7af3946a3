// renderReference: dense tessellation -> Embree triangles -> primary rays -> Newton onto the
// limit surface -> shaded passes; plus the supersampled coverage of the same triangles.
#include "render/oracle/reference.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <string>

#include "render/core/shading.h"
#include "render/oracle/ray_caster.h"
#include "render/oracle/reference_passes.h"
#include "render/oracle/reference_scene.h"
#include "render/oracle/reference_tessellation.h"
#include "render/oracle/surface_hit.h"
#include "render/oracle/triangle_scene.h"

namespace limn::render::oracle {

namespace {

using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// Newton stops when the point is this close to the ray, relative to the model's size.
constexpr double kRelativeTolerance = 1e-9;

// A ray's hit on the limit surface, from its hit on the dense tessellation (Newton).
SurfaceHit limitHit(const subdiv::LimitSurface& surface, const tessellate::TriangleMesh& mesh,
                    const PixelRay& ray, const PixelHit& h) {
  const double tolerance = kRelativeTolerance * std::max(surface.bounds().diagonal(), 1e-300);
  int face;
  Vec2 uv;
  return triangleHitUV(surface, mesh, h.primID, h.u, h.v, &face, &uv)
             ? refineHit(surface, face, uv, ray, h.t, tolerance)
             : unrefinedHit(surface, face, uv, ray, h.t);
}

// Moves every primary hit onto the limit surface (Newton) and writes the passes; counts hits
// and failures into result.stats, and warns about many failures.
void shadeHits(const subdiv::LimitSurface& surface, const Camera& camera,
               const tessellate::TriangleMesh& mesh, const std::vector<PixelHit>& hits,
               const PassSelection& passes, const CancelToken& cancel, ReferenceResult& result) {
  const int width = camera.width(), height = camera.height();
  PassImages images(result.images, passes, width, height);
  std::atomic<size_t> covered{0}, failures{0};
  std::atomic<bool> cancelled{false};
  tbb::parallel_for(tbb::blocked_range<int>(0, height, 4), [&](const tbb::blocked_range<int>& r) {
    if (cancelled || cancel.expired()) {
      cancelled = true;
      return;
    }
    size_t rowCovered = 0, rowFailures = 0;
    for (int y = r.begin(); y < r.end(); ++y) {
      for (int x = 0; x < width; ++x) {
        const PixelHit& h = hits[static_cast<size_t>(y) * width + x];
        if (!h.hit()) continue;
        SurfaceHit hit = limitHit(surface, mesh, pixelRay(camera, x + 0.5, y + 0.5), h);
        ++rowCovered;
        rowFailures += !hit.refined;
        images.write(x, y, hit, camera);
      }
    }
    covered += rowCovered;
    failures += rowFailures;
  });
  if (cancelled) throw Cancelled();
  ReferenceStats& stats = result.stats;
  stats.hits = covered;
  stats.newtonFailures = failures;
  if (stats.hits > 0 && stats.newtonFailures * 1000 > stats.hits) {
    result.warnings.push_back("reference: " + std::to_string(stats.newtonFailures) + " of " +
                              std::to_string(stats.hits) +
                              " hits could not be refined onto the limit surface (kept on the "
                              "dense tessellation)");
  }
}

}  // namespace

ReferenceResult renderReference(const subdiv::LimitSurface& surface, const Camera& camera,
                                const PassSelection& passes, const CancelToken& cancel,
                                const ReferenceOptions& options) {
  ReferenceResult result;
  ReferenceStats& stats = result.stats;

  std::shared_ptr<const ReferenceScene> built;
  if (options.cache) {
    built = options.cache->get(surface, camera, cancel, &stats.sceneCached, options.triangleBudget);
  } else {
    built = buildReferenceScene(surface, camera, cancel, options.triangleBudget);
  }
  const ReferenceTessellation& tessellation = built->tessellation;
  const tessellate::TriangleMesh& mesh = tessellation.mesh;
  result.coverageMesh = std::shared_ptr<const tessellate::TriangleMesh>(built, &mesh);
  RTCScene scene = built->scene.get();
  stats.triangles = mesh.triangleCount();
  stats.outlineFaces = tessellation.outlineFaces;
  stats.outlineErrorPx = tessellation.outlineErrorPx;
  if (!stats.sceneCached) {
    stats.tessellateMs = built->tessellateMs;
    stats.bvhMs = built->bvhMs;
  }
  // Every edge rate scaled by r leaves the chord error 1 / r^2 times larger.
  stats.accuracyPx =
      tessellation.outlineErrorPx / (tessellation.ratesScaled * tessellation.ratesScaled);
  if (stats.accuracyPx > kOutlineChordErrorPx * 1.0001) {
    result.warnings.push_back(
        "reference: outline chord error raised to " + std::to_string(stats.accuracyPx) +
        " px (from " + std::to_string(kOutlineChordErrorPx) + ") to stay within " +
        std::to_string(static_cast<long>(options.triangleBudget)) +
        " triangles: outline distances below that cannot be told from the reference's own error");
  }
  cancel.check();

  // Primary rays at pixel centres: the passes, and the coverage the supersampled mask starts from.
  auto start = Clock::now();
  std::vector<PixelHit> hits = castClosestHits(scene, camera, RayPacking::Packet16, cancel);
  stats.traceMs = msSince(start);
  stats.raysCast += hits.size();

  start = Clock::now();
  shadeHits(surface, camera, mesh, hits, passes, cancel, result);
  if ((passes.color || passes.wireframe) && options.colorSamples.size() > 1) {
    antialiasEdges(
        scene, camera, hits, options.colorSamples, cancel,
        [&](const PixelRay& ray, const PixelHit& h) { return limitHit(surface, mesh, ray, h); },
        result.images.passes.at(pass::kColor), stats);
  }
  colorAsWireframe(passes, "limit surface", result);
  stats.newtonMs = msSince(start);

  if (passes.supersample > 0) {
    start = Clock::now();
    castSupersampledMask(scene, camera, hits, passes.supersample, built->outlineCandidates, options,
                         cancel, result);
    stats.maskMs = msSince(start);
    if (options.locateOutline) {
      start = Clock::now();
      result.outline = metrics::locateOutline(result.images.supersampledMask, passes.supersample,
                                              coverageQuery(scene, camera, cancel), cancel,
                                              &result.refinedPixels);
      stats.outlineMs = msSince(start);
    }
  }
  return result;
}

metrics::Outline locateMeshOutline(const tessellate::TriangleMesh& mesh, const Camera& camera,
                                   const Image& supersampledMask, int supersample,
                                   const CancelToken& cancel, const std::vector<char>* scan) {
  EmbreeScene scene = buildTriangleScene(mesh, RTC_BUILD_QUALITY_LOW);
  cancel.check();
  return metrics::locateOutline(supersampledMask, supersample,
                                coverageQuery(scene.get(), camera, cancel), cancel, scan);
}

}  // namespace limn::render::oracle
