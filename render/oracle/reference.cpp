// renderReference: dense tessellation -> Embree triangles -> primary rays -> Newton onto the
// limit surface -> shaded passes; plus the supersampled coverage of the same triangles.
#include "render/oracle/reference.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

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

// Output pixels around a flagged one within which locateOutline's queries can fall (its cells
// reach a sample past the flagged blocks, its corner searches half a cell further).
constexpr int kScanMarginPx = 2;

// Per output pixel, how many flagged pixels lie in the rectangle from (0, 0) to it (exclusive):
// any rectangle's count from four reads.
class FlagCounts {
 public:
  FlagCounts(const std::vector<char>& flags, int width, int height)
      : width_(width), height_(height), sums_(static_cast<size_t>(width + 1) * (height + 1), 0) {
    for (int y = 0; y < height; ++y) {
      int row = 0;
      for (int x = 0; x < width; ++x) {
        row += flags[static_cast<size_t>(y) * width + x] != 0;
        at(x + 1, y + 1) = at(x + 1, y) + row;
      }
    }
  }
  // Whether any pixel of [x0, x1] x [y0, y1] (clamped to the image) is flagged.
  bool any(int x0, int y0, int x1, int y1) const {
    x0 = std::max(x0, 0);
    y0 = std::max(y0, 0);
    x1 = std::min(x1, width_ - 1);
    y1 = std::min(y1, height_ - 1);
    if (x0 > x1 || y0 > y1) return false;
    return at(x1 + 1, y1 + 1) - at(x0, y1 + 1) - at(x1 + 1, y0) + at(x0, y0) > 0;
  }

 private:
  int& at(int x, int y) { return sums_[static_cast<size_t>(y) * (width_ + 1) + x]; }
  int at(int x, int y) const { return sums_[static_cast<size_t>(y) * (width_ + 1) + x]; }
  int width_, height_;
  std::vector<int> sums_;
};

// The triangles whose screen bounding box comes within `marginPx` of a flagged output pixel,
// and every triangle reaching behind the near plane (its projection is no triangle). Of a mesh
// closed and wound outward that is wholly in front of the near plane, only the front faces:
// each back face lies behind a front face, so it covers nothing more (the rasteriser draws the
// same mesh's coverage without them), and near an outline they are half the triangles.
std::vector<uint32_t> trianglesNearPixels(const tessellate::TriangleMesh& mesh,
                                          const Camera& camera, const std::vector<char>& flags,
                                          int marginPx) {
  const int width = camera.width(), height = camera.height();
  if (flags.size() != static_cast<size_t>(width) * height) {
    throw std::invalid_argument("trianglesNearPixels: one flag per output pixel expected");
  }
  const FlagCounts counts(flags, width, height);
  std::vector<Vec3> projected(mesh.positions.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, projected.size(), 8192),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t v = r.begin(); v < r.end(); ++v) {
                        projected[v] = camera.project(mesh.positions[v].toDouble());
                      }
                    });
  const bool frontFacesOnly =
      mesh.closedOutward && std::all_of(projected.begin(), projected.end(),
                                        [&](const Vec3& p) { return p.z > camera.nearPlane(); });
  const size_t triangles = mesh.triangleCount();
  std::vector<char> keep(triangles, 0);
  tbb::parallel_for(
      tbb::blocked_range<size_t>(0, triangles, 8192), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t t = r.begin(); t < r.end(); ++t) {
          const Vec3& a = projected[mesh.indices[3 * t]];
          const Vec3& b = projected[mesh.indices[3 * t + 1]];
          const Vec3& c = projected[mesh.indices[3 * t + 2]];
          const double near = camera.nearPlane();
          if (!(a.z > near && b.z > near && c.z > near)) {
            keep[t] = 1;
            continue;
          }
          // Image y runs down: a face wound counter-clockwise towards the eye turns clockwise.
          if (frontFacesOnly && !(cross2(Vec2{a.x, a.y}, Vec2{b.x, b.y}, Vec2{c.x, c.y}) < 0)) {
            continue;
          }
          // Boxes far outside the image clamp to nothing; NaNs are kept.
          const double x0 = std::min({a.x, b.x, c.x}), x1 = std::max({a.x, b.x, c.x});
          const double y0 = std::min({a.y, b.y, c.y}), y1 = std::max({a.y, b.y, c.y});
          if (!(x0 <= x1 && y0 <= y1)) {
            keep[t] = 1;
            continue;
          }
          const double limit = 1e6;
          keep[t] =
              counts.any(static_cast<int>(std::floor(std::clamp(x0, -limit, limit))) - marginPx,
                         static_cast<int>(std::floor(std::clamp(y0, -limit, limit))) - marginPx,
                         static_cast<int>(std::floor(std::clamp(x1, -limit, limit))) + marginPx,
                         static_cast<int>(std::floor(std::clamp(y1, -limit, limit))) + marginPx);
        }
      });
  std::vector<uint32_t> kept;
  for (size_t t = 0; t < triangles; ++t) {
    if (keep[t]) kept.push_back(static_cast<uint32_t>(t));
  }
  return kept;
}

}  // namespace

BegunReference beginReference(const subdiv::LimitSurface& surface, const Camera& camera,
                              const PassSelection& passes, const CancelToken& cancel,
                              const ReferenceOptions& options) {
  BegunReference begun;
  ReferenceResult& result = begun.result;
  ReferenceStats& stats = result.stats;

  if (options.cache) {
    begun.scene =
        options.cache->get(surface, camera, cancel, &stats.sceneCached, options.triangleBudget);
  } else {
    begun.scene = buildReferenceScene(surface, camera, cancel, options.triangleBudget);
  }
  const ReferenceTessellation& tessellation = begun.scene->tessellation;
  const tessellate::TriangleMesh& mesh = tessellation.mesh;
  result.coverageMesh = std::shared_ptr<const tessellate::TriangleMesh>(begun.scene, &mesh);
  RTCScene scene = begun.scene->scene.get();
  stats.triangles = mesh.triangleCount();
  stats.outlineFaces = tessellation.outlineFaces;
  stats.outlineErrorPx = tessellation.outlineErrorPx;
  if (!stats.sceneCached) {
    stats.tessellateMs = begun.scene->tessellateMs;
    stats.bvhMs = begun.scene->bvhMs;
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
  begun.hits = castClosestHits(scene, camera, RayPacking::Packet16, cancel);
  stats.traceMs = msSince(start);
  stats.raysCast += begun.hits.size();

  start = Clock::now();
  shadeHits(surface, camera, mesh, begun.hits, passes, cancel, result);
  if ((passes.color || passes.wireframe) && options.colorSamples.size() > 1) {
    antialiasEdges(
        scene, camera, begun.hits, options.colorSamples, cancel,
        [&](const PixelRay& ray, const PixelHit& h) { return limitHit(surface, mesh, ray, h); },
        result.images.passes.at(pass::kColor), stats);
  }
  colorAsWireframe(passes, "limit surface", result);
  stats.newtonMs = msSince(start);
  return begun;
}

ReferenceResult finishReference(BegunReference begun, const Camera& camera,
                                const PassSelection& passes, const CancelToken& cancel,
                                const ReferenceOptions& options) {
  ReferenceResult& result = begun.result;
  if (passes.supersample > 0) {
    RTCScene scene = begun.scene->scene.get();
    auto start = Clock::now();
    castSupersampledMask(scene, camera, begun.hits, passes.supersample,
                         begun.scene->outlineCandidates, options, cancel, result);
    result.stats.maskMs = msSince(start);
    if (options.locateOutline) {
      start = Clock::now();
      result.outline = metrics::locateOutline(result.images.supersampledMask, passes.supersample,
                                              coverageQuery(scene, camera, cancel), cancel,
                                              &result.refinedPixels);
      result.stats.outlineMs = msSince(start);
    }
  }
  return std::move(result);
}

ReferenceResult renderReference(const subdiv::LimitSurface& surface, const Camera& camera,
                                const PassSelection& passes, const CancelToken& cancel,
                                const ReferenceOptions& options) {
  return finishReference(beginReference(surface, camera, passes, cancel, options), camera, passes,
                         cancel, options);
}

metrics::Outline locateMeshOutline(const tessellate::TriangleMesh& mesh, const Camera& camera,
                                   const Mask& supersampledMask, int supersample,
                                   const CancelToken& cancel, const std::vector<char>* scan) {
  // With `scan`, every point queried lies within a pixel of a flagged one, and a ray there can
  // only hit a triangle whose screen box reaches that far: the scene needs those triangles
  // alone (a few percent of an approximation's), and answers every query as the whole mesh's
  // scene would (each ray's test against a triangle does not depend on the others).
  std::vector<uint32_t> nearScan;
  if (scan) nearScan = trianglesNearPixels(mesh, camera, *scan, kScanMarginPx);
  EmbreeScene scene = buildTriangleScene(mesh, RTC_BUILD_QUALITY_LOW, scan ? &nearScan : nullptr);
  cancel.check();
  return metrics::locateOutline(supersampledMask, supersample,
                                coverageQuery(scene.get(), camera, cancel), cancel, scan);
}

}  // namespace limn::render::oracle
