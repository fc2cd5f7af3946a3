// contourVisibility: the reference tessellation in an Embree scene, and two occlusion rays per
// contour point offset to either side of it (see visibility.h for why).
#include "render/oracle/visibility.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>

#include "render/core/parallel.h"
#include "render/oracle/embree_device.h"
#include "render/oracle/reference_tessellation.h"
#include "render/oracle/triangle_scene.h"

namespace limn::render::oracle {

namespace {

using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// Whether the view of `target` from the camera is blocked before `margin` short of it.
bool blocked(RTCScene scene, const Camera& camera, const Vec3& target, double margin) {
  if (camera.projection() == Projection::Perspective) {
    Vec3 toTarget = target - camera.eye();
    double distance = length(toTarget);
    if (!(distance > 0)) return false;
    Vec3 d = toTarget / distance;
    double cosine = dot(d, camera.forward());
    if (!(cosine > 0)) return false;  // behind the eye: not in the picture
    double tNear = camera.nearPlane() / cosine;
    double tFar = std::min(distance - margin, camera.farPlane() / cosine);
    return tFar > tNear && rayOccluded(scene, camera.eye(), d, tNear, tFar);
  }
  // Orthographic: from the near plane along the view direction.
  const Vec3& d = camera.forward();
  double depth = camera.depthOf(target);
  Vec3 origin = target - d * (depth - camera.nearPlane());
  double tFar = std::min(depth - margin, camera.farPlane()) - camera.nearPlane();
  return tFar > 0 && rayOccluded(scene, origin, d, 0.0, tFar);
}

// The unit vector along `normal` with its component along the view ray at `p` removed.
Vec3 sideways(const Camera& camera, const Vec3& p, const Vec3& normal) {
  Vec3 ray = normalize(camera.viewVector(p));
  Vec3 m = normal - ray * dot(normal, ray);
  double len = length(m);
  if (len > 1e-9) return m / len;
  // A normal along the ray is no contour normal; any direction across the ray will do.
  return normalize(camera.right() - ray * dot(camera.right(), ray));
}

}  // namespace

bool rayOccluded(RTCScene scene, const Vec3& origin, const Vec3& direction, double tNear,
                 double tFar) {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay ray;
  ray.org_x = static_cast<float>(origin.x);
  ray.org_y = static_cast<float>(origin.y);
  ray.org_z = static_cast<float>(origin.z);
  ray.dir_x = static_cast<float>(direction.x);
  ray.dir_y = static_cast<float>(direction.y);
  ray.dir_z = static_cast<float>(direction.z);
  ray.tnear = static_cast<float>(tNear);
  ray.tfar = static_cast<float>(tFar);
  ray.time = 0.0f;
  ray.mask = 0xFFFFFFFFu;
  ray.id = 0;
  ray.flags = 0;
  rtcOccluded1(scene, &context, &ray);
  return ray.tfar < 0.0f;  // Embree sets tfar to -inf when the ray hit something
}

std::vector<bool> contourVisibility(const subdiv::LimitSurface& surface, const Camera& camera,
                                    const std::vector<VisibilityPoint>& points,
                                    const VisibilityOptions& options, const CancelToken& cancel,
                                    VisibilityStats* stats) {
  VisibilityStats local;
  VisibilityStats& s = stats ? *stats : local;
  s = {};

  auto start = Clock::now();
  ReferenceTessellation tessellation = tessellateForReference(surface, camera, cancel);
  s.triangles = tessellation.mesh.triangleCount();
  s.outlineErrorPx = tessellation.outlineErrorPx;
  s.tessellateMs = msSince(start);
  cancel.check();

  start = Clock::now();
  // Few rays: a LOW quality BVH builds fastest (triangle_scene.h's measurements).
  EmbreeScene scene = buildTriangleScene(tessellation.mesh, RTC_BUILD_QUALITY_LOW);
  s.bvhMs = msSince(start);
  cancel.check();

  start = Clock::now();
  // Eight times the chord error keeps the offset ray clear of the chords it passes.
  const double offsetPx =
      options.offsetPx > 0 ? std::max(options.offsetPx, 8 * tessellation.outlineErrorPx) : 0.0;
  std::vector<char> visible(points.size(), 1);
  std::atomic<size_t> rays{0};
  parallelFor(points.size(), 256, [&](size_t begin, size_t end) {
    cancel.check();
    FlushDenormalsScope ftz;
    size_t cast = 0;
    for (size_t i = begin; i < end; ++i) {
      const VisibilityPoint& p = points[i];
      ++cast;
      if (offsetPx == 0) {
        visible[i] = !blocked(scene.get(), camera, p.position, 0.0);
        continue;
      }
      double delta = offsetPx / camera.pixelsPerUnit(camera.depthOf(p.position)) + p.slack;
      Vec3 m = sideways(camera, p.position, p.normal);
      // The second ray only matters when the first is blocked.
      if (!blocked(scene.get(), camera, p.position + m * delta, delta)) continue;
      ++cast;
      visible[i] = !blocked(scene.get(), camera, p.position - m * delta, delta);
    }
    rays += cast;
  });
  cancel.check();
  s.traceMs = msSince(start);

  std::vector<bool> out(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    out[i] = visible[i] != 0;
    s.hidden += !out[i];
  }
  s.raysCast = rays;
  return out;
}

}  // namespace limn::render::oracle
