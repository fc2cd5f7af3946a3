// renderReference: dense tessellation -> Embree triangles -> primary rays -> Newton onto the
// limit surface -> shaded passes; plus the supersampled coverage of the same triangles.
#include "render/oracle/reference.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <chrono>
#include <string>

#include "render/core/shading.h"
#include "render/oracle/ray_caster.h"
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

// The output images of the selected passes, filled pixel by pixel.
struct PassImages {
  Image* color = nullptr;
  Image* mask = nullptr;
  Image* depth = nullptr;
  Image* normal = nullptr;

  PassImages(ImageSet& set, const PassSelection& passes, int width, int height) {
    if (passes.color || passes.wireframe) {
      color = &set.passes[pass::kColor];
      *color = Image(width, height, 4);
      for (size_t i = 0; i < color->pixels.size(); i += 4) {
        for (int c = 0; c < 3; ++c) color->pixels[i + c] = shading::kBackground[c];
        color->pixels[i + 3] = 0.0f;
      }
    }
    if (passes.mask) mask = &(set.passes[pass::kMask] = Image(width, height, 1));
    if (passes.depth) depth = &(set.passes[pass::kDepth] = Image(width, height, 1));
    if (passes.normal) normal = &(set.passes[pass::kNormal] = Image(width, height, 3));
  }

  void write(int x, int y, const SurfaceHit& hit, const Camera& camera) {
    if (mask) mask->at(x, y) = 1.0f;
    if (depth) depth->at(x, y) = static_cast<float>(camera.depthOf(hit.position));
    if (normal) {
      normal->at(x, y, 0) = static_cast<float>(hit.normal.x);
      normal->at(x, y, 1) = static_cast<float>(hit.normal.y);
      normal->at(x, y, 2) = static_cast<float>(hit.normal.z);
    }
    if (color) {
      Vec3 toEye = camera.projection() == Projection::Perspective
                       ? normalize(camera.eye() - hit.position)
                       : -camera.forward();
      float rgb[3];
      shading::shade(hit.normal, toEye, rgb);
      for (int c = 0; c < 3; ++c) color->at(x, y, c) = rgb[c];
      color->at(x, y, 3) = 1.0f;
    }
  }
};

bool wantsPrimary(const PassSelection& p) {
  return p.color || p.mask || p.depth || p.normal || p.wireframe;
}

}  // namespace

ReferenceResult renderReference(const subdiv::LimitSurface& surface, const Camera& camera,
                                const PassSelection& passes, const CancelToken& cancel) {
  ReferenceResult result;
  ReferenceStats& stats = result.stats;

  auto start = Clock::now();
  ReferenceTessellation tessellation = tessellateForReference(surface, camera, cancel);
  const tessellate::TriangleMesh& mesh = tessellation.mesh;
  stats.triangles = mesh.triangleCount();
  stats.outlineFaces = tessellation.outlineFaces;
  stats.outlineErrorPx = tessellation.outlineErrorPx;
  if (tessellation.outlineErrorPx > kOutlineChordErrorPx * 1.0001) {
    result.warnings.push_back(
        "reference: outline chord error raised to " + std::to_string(tessellation.outlineErrorPx) +
        " px (from " + std::to_string(kOutlineChordErrorPx) + ") to stay within " +
        std::to_string(static_cast<long>(kReferenceTriangleBudget)) + " triangles");
  }
  stats.tessellateMs = msSince(start);
  cancel.check();

  start = Clock::now();
  // Build quality: see triangle_scene.h for the measurements behind this choice.
  EmbreeScene scene = buildTriangleScene(
      mesh, passes.supersample > 0 ? RTC_BUILD_QUALITY_HIGH : RTC_BUILD_QUALITY_LOW);
  stats.bvhMs = msSince(start);
  cancel.check();

  if (wantsPrimary(passes)) {
    const int width = camera.width(), height = camera.height();
    start = Clock::now();
    std::vector<PixelHit> hits = castClosestHits(scene.get(), camera, RayPacking::Packet16, cancel);
    stats.traceMs = msSince(start);
    stats.raysCast += hits.size();

    start = Clock::now();
    PassImages images(result.images, passes, width, height);
    const double tolerance = kRelativeTolerance * std::max(surface.bounds().diagonal(), 1e-300);
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
          PixelRay ray = pixelRay(camera, x + 0.5, y + 0.5);
          int face;
          Vec2 uv;
          SurfaceHit hit = triangleHitUV(surface, mesh, h.primID, h.u, h.v, &face, &uv)
                               ? refineHit(surface, face, uv, ray, h.t, tolerance)
                               : unrefinedHit(surface, face, uv, ray, h.t);
          ++rowCovered;
          rowFailures += !hit.refined;
          images.write(x, y, hit, camera);
        }
      }
      covered += rowCovered;
      failures += rowFailures;
    });
    if (cancelled) throw Cancelled();
    stats.hits = covered;
    stats.newtonFailures = failures;
    stats.newtonMs = msSince(start);
    if (passes.wireframe) {
      result.images.passes[pass::kWireframe] = result.images.passes[pass::kColor];
      if (!passes.color) result.images.passes.erase(pass::kColor);
      result.warnings.push_back(
          "reference wireframe: the limit surface has no edges; the pass is the shaded color");
    }
    if (stats.hits > 0 && stats.newtonFailures * 1000 > stats.hits) {
      result.warnings.push_back("reference: " + std::to_string(stats.newtonFailures) + " of " +
                                std::to_string(stats.hits) +
                                " hits could not be refined onto the limit surface (kept on the "
                                "dense tessellation)");
    }
  }

  if (passes.supersample > 0) {
    start = Clock::now();
    Camera fine = camera.scaled(passes.supersample);
    result.images.supersampledMask =
        castCoverage(scene.get(), fine, RayPacking::Packet16, cancel);
    result.images.supersample = passes.supersample;
    stats.raysCast += static_cast<size_t>(fine.width()) * fine.height();
    stats.maskMs = msSince(start);
  }
  return result;
}

}  // namespace limn::render::oracle
