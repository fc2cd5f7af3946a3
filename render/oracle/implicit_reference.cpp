#include "render/oracle/implicit_reference.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>

#include "render/oracle/ray_caster.h"
#include "render/oracle/reference_passes.h"

namespace limn::render::oracle {

namespace {

using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

constexpr int kMaxSteps = 20000;

// What the Embree callbacks need: the boxes, one field evaluator per thread, the step bounds.
struct IsosurfaceScene {
  const implicit::Field* field;
  std::vector<Bounds> boxes;
  // The smallest step: the lesser of minStep and a quarter pixel's footprint at the ray's
  // distance t (footprintPerT * t + footprintAtZero, output pixels).
  double minStep, maxStep, tolerance;
  double footprintPerT = 0, footprintAtZero = 0;
  tbb::enumerable_thread_specific<implicit::FieldEvaluator> evaluators;
  std::atomic<size_t> exhausted{0};  // searches that ran out of steps

  explicit IsosurfaceScene(const implicit::Field& f)
      : field(&f), evaluators([&f] { return implicit::FieldEvaluator(f); }) {}
};

// The first t in [t0, t1] where F - iso changes sign along o + t d (|d| = 1), or -1; `refine`
// false stops at the bracket (an occlusion ray only needs to know there is one). When the
// stretch starts inside (F > iso) after the ray's own start, an earlier box holds the crossing
// that matters and this one is skipped.
double firstCrossing(IsosurfaceScene& scene, implicit::FieldEvaluator& f, const Vec3& o,
                     const Vec3& d, double t0, double t1, bool rayStartsHere, bool refine) {
  double t = t0, ft = f.value(o + d * t);
  if (ft > 0 && !rayStartsHere) return -1;
  const bool inside = ft > 0;
  for (int i = 0; i < kMaxSteps; ++i) {
    const Vec3 p = o + d * t;
    const double lipschitz = f.lipschitzNear(p, scene.maxStep);
    double step = lipschitz > 0 ? std::fabs(ft) / lipschitz : scene.maxStep;
    const double floor =
        std::min(scene.minStep, 0.25 * (scene.footprintPerT * t + scene.footprintAtZero));
    step = std::clamp(step, floor, scene.maxStep);
    const double tn = std::min(t + step, t1);
    const double fn = f.value(o + d * tn);
    if ((fn > 0) != inside) {
      return refine ? implicit::rootOnSegment(f, o, d, t, ft, tn, fn, scene.tolerance) : tn;
    }
    if (tn >= t1) return -1;
    t = tn;
    ft = fn;
  }
  ++scene.exhausted;
  return -1;
}

// The ray's stretch inside a box (slab test), clipped to [tnear, tfar].
bool clipToBox(const Bounds& box, const Vec3& o, const Vec3& d, double& t0, double& t1) {
  for (int a = 0; a < 3; ++a) {
    if (d[a] == 0) {
      if (o[a] < box.lo[a] || o[a] > box.hi[a]) return false;
      continue;
    }
    double ta = (box.lo[a] - o[a]) / d[a], tb = (box.hi[a] - o[a]) / d[a];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  return t0 <= t1;
}

struct LaneRay {
  Vec3 o, d;
  double scale;  // |direction| as Embree holds it: t along the float direction = world / scale
  double tnear, tfar;
};

LaneRay laneRay(RTCRayN* ray, unsigned N, unsigned i) {
  LaneRay r;
  r.o = {RTCRayN_org_x(ray, N, i), RTCRayN_org_y(ray, N, i), RTCRayN_org_z(ray, N, i)};
  const Vec3 dir{RTCRayN_dir_x(ray, N, i), RTCRayN_dir_y(ray, N, i), RTCRayN_dir_z(ray, N, i)};
  r.scale = length(dir);
  r.d = dir / r.scale;
  r.tnear = RTCRayN_tnear(ray, N, i) * r.scale;
  r.tfar = RTCRayN_tfar(ray, N, i) * r.scale;
  return r;
}

// The crossing of lane i's ray in box primID, in Embree's t, or -1.
double laneCrossing(IsosurfaceScene& scene, unsigned primID, const LaneRay& r, bool refine) {
  double t0 = r.tnear, t1 = r.tfar;
  if (!clipToBox(scene.boxes[primID], r.o, r.d, t0, t1)) return -1;
  implicit::FieldEvaluator& f = scene.evaluators.local();
  const double t = firstCrossing(scene, f, r.o, r.d, t0, t1, t0 <= r.tnear, refine);
  return t < 0 ? -1 : t / r.scale;
}

void boundsCallback(const RTCBoundsFunctionArguments* args) {
  const auto* scene = static_cast<const IsosurfaceScene*>(args->geometryUserPtr);
  const Bounds& box = scene->boxes[args->primID];
  // Rounded outwards so the float box holds the double one.
  args->bounds_o->lower_x = std::nextafter(static_cast<float>(box.lo.x), -1e30f);
  args->bounds_o->lower_y = std::nextafter(static_cast<float>(box.lo.y), -1e30f);
  args->bounds_o->lower_z = std::nextafter(static_cast<float>(box.lo.z), -1e30f);
  args->bounds_o->upper_x = std::nextafter(static_cast<float>(box.hi.x), 1e30f);
  args->bounds_o->upper_y = std::nextafter(static_cast<float>(box.hi.y), 1e30f);
  args->bounds_o->upper_z = std::nextafter(static_cast<float>(box.hi.z), 1e30f);
}

void intersectCallback(const RTCIntersectFunctionNArguments* args) {
  auto* scene = static_cast<IsosurfaceScene*>(args->geometryUserPtr);
  RTCRayN* ray = RTCRayHitN_RayN(args->rayhit, args->N);
  RTCHitN* hit = RTCRayHitN_HitN(args->rayhit, args->N);
  for (unsigned i = 0; i < args->N; ++i) {
    if (!args->valid[i]) continue;
    const double t = laneCrossing(*scene, args->primID, laneRay(ray, args->N, i), true);
    if (t < 0 || t >= RTCRayN_tfar(ray, args->N, i)) continue;
    RTCRayN_tfar(ray, args->N, i) = static_cast<float>(t);
    RTCHitN_u(hit, args->N, i) = 0;
    RTCHitN_v(hit, args->N, i) = 0;
    RTCHitN_Ng_x(hit, args->N, i) = 0;
    RTCHitN_Ng_y(hit, args->N, i) = 0;
    RTCHitN_Ng_z(hit, args->N, i) = 1;
    RTCHitN_primID(hit, args->N, i) = args->primID;
    RTCHitN_geomID(hit, args->N, i) = args->geomID;
    RTCHitN_instID(hit, args->N, i, 0) = args->context->instID[0];
  }
}

void occludedCallback(const RTCOccludedFunctionNArguments* args) {
  auto* scene = static_cast<IsosurfaceScene*>(args->geometryUserPtr);
  for (unsigned i = 0; i < args->N; ++i) {
    if (!args->valid[i]) continue;
    if (laneCrossing(*scene, args->primID, laneRay(args->ray, args->N, i), false) >= 0) {
      RTCRayN_tfar(args->ray, args->N, i) = -std::numeric_limits<float>::infinity();
    }
  }
}

EmbreeScene buildScene(IsosurfaceScene& data) {
  RTCDevice device = embreeDevice();
  RTCScene scene = rtcNewScene(device);
  rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST);
  RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_USER);
  rtcSetGeometryUserPrimitiveCount(geometry, static_cast<unsigned>(data.boxes.size()));
  rtcSetGeometryUserData(geometry, &data);
  rtcSetGeometryBoundsFunction(geometry, boundsCallback, nullptr);
  rtcSetGeometryIntersectFunction(geometry, intersectCallback);
  rtcSetGeometryOccludedFunction(geometry, occludedCallback);
  rtcCommitGeometry(geometry);
  rtcAttachGeometry(scene, geometry);
  rtcReleaseGeometry(geometry);
  rtcCommitScene(scene);
  checkEmbree("implicit scene");
  return EmbreeScene(scene);
}

// The boxes of the positive primitives, clipped to the field's domain.
std::vector<Bounds> positiveBoxes(const implicit::Field& field) {
  std::vector<Bounds> boxes;
  const Bounds& domain = field.bounds();
  for (const implicit::PreparedPrimitive& prim : field.primitives()) {
    if (prim.sign < 0) continue;
    Bounds box;
    box.lo = {std::max(prim.support.lo.x, domain.lo.x), std::max(prim.support.lo.y, domain.lo.y),
              std::max(prim.support.lo.z, domain.lo.z)};
    box.hi = {std::min(prim.support.hi.x, domain.hi.x), std::min(prim.support.hi.y, domain.hi.y),
              std::min(prim.support.hi.z, domain.hi.z)};
    if (!box.empty()) boxes.push_back(box);
  }
  // Overlapping boxes are merged (repeatedly, into their common bounding box): a ray through
  // several overlapping boxes would otherwise march the same stretch once for each.
  for (bool merged = true; merged;) {
    merged = false;
    for (size_t a = 0; a < boxes.size() && !merged; ++a) {
      for (size_t b = a + 1; b < boxes.size() && !merged; ++b) {
        const Bounds& p = boxes[a];
        const Bounds& q = boxes[b];
        if (p.lo.x <= q.hi.x && q.lo.x <= p.hi.x && p.lo.y <= q.hi.y && q.lo.y <= p.hi.y &&
            p.lo.z <= q.hi.z && q.lo.z <= p.hi.z) {
          boxes[a].extend(q.lo);
          boxes[a].extend(q.hi);
          boxes.erase(boxes.begin() + static_cast<long>(b));
          merged = true;
        }
      }
    }
  }
  return boxes;
}

// The hit of a pixel's ray in double precision, around Embree's t.
SurfaceHit exactHit(implicit::FieldEvaluator& f, const PixelRay& ray, double t, double bracket,
                    double tolerance) {
  const Vec3 o = ray.origin, d = ray.direction;
  double t0 = std::max(ray.tNear, t - bracket), t1 = t + bracket;
  const double f0 = f.value(o + d * t0), f1 = f.value(o + d * t1);
  SurfaceHit hit;
  hit.t = t;
  if ((f0 > 0) != (f1 > 0)) {
    hit.t = implicit::rootOnSegment(f, o, d, t0, f0, t1, f1, tolerance);
    hit.refined = true;
  }
  hit.position = o + d * hit.t;
  hit.normal = f.normal(hit.position);
  return hit;
}

}  // namespace

ReferenceResult renderImplicitReference(const implicit::Field& field, const Camera& camera,
                                        const PassSelection& passes, const CancelToken& cancel,
                                        const ReferenceOptions& options) {
  ReferenceResult result;
  ReferenceStats& stats = result.stats;
  const double diagonal = std::max(field.bounds().diagonal(), 1e-300);

  auto start = Clock::now();
  IsosurfaceScene data(field);
  data.boxes = positiveBoxes(field);
  data.minStep = 1e-4 * diagonal;
  data.maxStep = std::min(0.05 * diagonal, field.localReach());
  // A pixel's footprint at distance t along a ray (output pixels).
  if (camera.projection() == Projection::Perspective) {
    data.footprintPerT = 2.0 * std::tan(camera.fovYDeg() * M_PI / 360.0) / camera.height();
  } else {
    data.footprintAtZero = camera.orthoHeight() / camera.height();
  }
  data.tolerance = 1e-7 * diagonal;  // Embree's float t holds no more
  EmbreeScene scene = buildScene(data);
  stats.bvhMs = msSince(start);
  cancel.check();

  start = Clock::now();
  std::vector<PixelHit> hits = castClosestHits(scene.get(), camera, RayPacking::Packet16, cancel);
  stats.traceMs = msSince(start);
  stats.raysCast += hits.size();

  start = Clock::now();
  const int width = camera.width(), height = camera.height();
  PassImages images(result.images, passes, width, height);
  std::atomic<size_t> covered{0}, unrefined{0};
  std::atomic<bool> cancelled{false};
  tbb::parallel_for(tbb::blocked_range<int>(0, height, 4), [&](const tbb::blocked_range<int>& r) {
    if (cancelled || cancel.expired()) {
      cancelled = true;
      return;
    }
    implicit::FieldEvaluator& f = data.evaluators.local();
    for (int y = r.begin(); y < r.end(); ++y) {
      for (int x = 0; x < width; ++x) {
        const PixelHit& h = hits[static_cast<size_t>(y) * width + x];
        if (!h.hit()) continue;
        SurfaceHit hit =
            exactHit(f, pixelRay(camera, x + 0.5, y + 0.5), h.t, 1e-5 * diagonal, 1e-9 * diagonal);
        ++covered;
        unrefined += !hit.refined;
        images.write(x, y, hit, camera);
      }
    }
  });
  if (cancelled) throw Cancelled();
  stats.hits = covered;
  stats.newtonFailures = unrefined;
  if ((passes.color || passes.wireframe) && options.colorSamples.size() > 1) {
    antialiasEdges(
        scene.get(), camera, hits, options.colorSamples, cancel,
        [&](const PixelRay& ray, const PixelHit& h) {
          return exactHit(data.evaluators.local(), ray, h.t, 1e-5 * diagonal, 1e-9 * diagonal);
        },
        result.images.passes.at(pass::kColor), stats);
  }
  stats.newtonMs = msSince(start);
  colorAsWireframe(passes, "isosurface", result);

  if (passes.supersample > 0) {
    start = Clock::now();
    const int s = passes.supersample;
    // No outline candidates are known beforehand: mixed coverage and the hint decide.
    castSupersampledMask(scene.get(), camera, hits, s, {}, options, cancel, result);
    stats.maskMs = msSince(start);
    if (options.locateOutline) {
      start = Clock::now();
      result.outline = metrics::locateOutline(result.images.supersampledMask, s,
                                              coverageQuery(scene.get(), camera, cancel), cancel,
                                              &result.refinedPixels);
      stats.outlineMs = msSince(start);
    }
  }
  if (data.exhausted > 0) {
    result.warnings.push_back("reference: " + std::to_string(data.exhausted.load()) +
                              " ray searches ran out of steps (counted as misses)");
  }
  return result;
}

}  // namespace limn::render::oracle
