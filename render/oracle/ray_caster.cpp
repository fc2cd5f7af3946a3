#include "render/oracle/ray_caster.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <limits>

#include "render/core/error.h"
#include "render/core/huge_pages.h"
#include "render/oracle/embree_device.h"

namespace limn::render::oracle {

namespace {

constexpr int kBlock = 4;  // packets cover kBlock x kBlock pixels

// Runs body(y0, y1) over bands of kBlock rows on all threads, with FTZ/DAZ set and the cancel
// token checked before every band.
template <typename Body>
void forEachBand(int height, const CancelToken& cancel, const Body& body) {
  const int bands = (height + kBlock - 1) / kBlock;
  std::atomic<bool> cancelled{false};
  tbb::parallel_for(tbb::blocked_range<int>(0, bands, 1), [&](const tbb::blocked_range<int>& r) {
    FlushDenormalsScope ftz;
    for (int band = r.begin(); band < r.end(); ++band) {
      if (cancelled.load(std::memory_order_relaxed) || cancel.expired()) {
        cancelled = true;
        return;
      }
      body(band * kBlock, std::min(height, (band + 1) * kBlock));
    }
  });
  if (cancelled) throw Cancelled();
}

// Runs body(begin, end, context) over chunks of [0, count) on all threads, with FTZ/DAZ set, an
// intersect context per chunk and the cancel token checked before each.
template <typename Body>
void forEachChunk(size_t count, size_t grain, const CancelToken& cancel, const Body& body) {
  std::atomic<bool> cancelled{false};
  tbb::parallel_for(tbb::blocked_range<size_t>(0, count, grain),
                    [&](const tbb::blocked_range<size_t>& r) {
                      if (cancelled.load(std::memory_order_relaxed) || cancel.expired()) {
                        cancelled = true;
                        return;
                      }
                      FlushDenormalsScope ftz;
                      RTCIntersectContext context;
                      rtcInitIntersectContext(&context);
                      body(r.begin(), r.end(), context);
                    });
  if (cancelled) throw Cancelled();
}

// Fills lane `k` of a ray packet (or a single ray through the same fields) with a pixel's ray.
// Embree gets the ray from its near point on, so tnear is 0 and t is measured from there.
template <typename RayN>
void setLane(RayN& ray, int k, const PixelRay& r) {
  Vec3 o = r.origin + r.direction * r.tNear;
  ray.org_x[k] = static_cast<float>(o.x);
  ray.org_y[k] = static_cast<float>(o.y);
  ray.org_z[k] = static_cast<float>(o.z);
  ray.dir_x[k] = static_cast<float>(r.direction.x);
  ray.dir_y[k] = static_cast<float>(r.direction.y);
  ray.dir_z[k] = static_cast<float>(r.direction.z);
  ray.tnear[k] = 0.0f;
  ray.tfar[k] = static_cast<float>(r.tFar - r.tNear);
  ray.time[k] = 0.0f;
  ray.mask[k] = 0xFFFFFFFFu;
  ray.id[k] = static_cast<unsigned>(k);
  ray.flags[k] = 0;
}

void setRay(RTCRay& ray, const PixelRay& r) {
  Vec3 o = r.origin + r.direction * r.tNear;
  ray.org_x = static_cast<float>(o.x);
  ray.org_y = static_cast<float>(o.y);
  ray.org_z = static_cast<float>(o.z);
  ray.dir_x = static_cast<float>(r.direction.x);
  ray.dir_y = static_cast<float>(r.direction.y);
  ray.dir_z = static_cast<float>(r.direction.z);
  ray.tnear = 0.0f;
  ray.tfar = static_cast<float>(r.tFar - r.tNear);
  ray.time = 0.0f;
  ray.mask = 0xFFFFFFFFu;
  ray.id = 0;
  ray.flags = 0;
}

// Visits the 4 x 4 blocks of rows [y0, y1): fn(x0, y0, lanePixel) with lanePixel(k) giving the
// pixel of lane k or false when the lane lies outside the image.
struct Block {
  int x0, y0, width, height;
  bool pixel(int k, int& x, int& y) const {
    x = x0 + k % kBlock;
    y = y0 + k / kBlock;
    return x < width && y < height;
  }
};

}  // namespace

PixelRay pixelRay(const Camera& camera, double px, double py) {
  Ray ray = camera.rayThrough(px, py);
  // Depth along the view is t * cos(angle to the forward axis): clip at near and far depth.
  double cosine = dot(ray.direction, camera.forward());
  PixelRay r{ray.origin, ray.direction, camera.nearPlane() / cosine, camera.farPlane() / cosine};
  if (camera.projection() == Projection::Perspective) r.tNear = std::max(r.tNear, 0.0);
  return r;
}

std::vector<PixelHit> castClosestHits(RTCScene scene, const Camera& camera, RayPacking packing,
                                      const CancelToken& cancel) {
  const int width = camera.width(), height = camera.height();
  std::vector<PixelHit> hits;
  assignOnHugePages(hits, static_cast<size_t>(width) * height, PixelHit{});
  forEachBand(height, cancel, [&](int y0, int y1) {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    for (int x0 = 0; x0 < width; x0 += kBlock) {
      Block block{x0, y0, width, y1};
      PixelRay rays[kBlock * kBlock];
      if (packing == RayPacking::Packet16) {
        alignas(64) int valid[16];
        alignas(64) RTCRayHit16 packet;
        for (int k = 0; k < 16; ++k) {
          int x, y;
          valid[k] = block.pixel(k, x, y) ? -1 : 0;
          rays[k] = pixelRay(camera, valid[k] ? x + 0.5 : x0 + 0.5, valid[k] ? y + 0.5 : y0 + 0.5);
          setLane(packet.ray, k, rays[k]);
          packet.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
          packet.hit.primID[k] = RTC_INVALID_GEOMETRY_ID;
        }
        rtcIntersect16(valid, scene, &context, &packet);
        for (int k = 0; k < 16; ++k) {
          int x, y;
          if (!block.pixel(k, x, y) || packet.hit.geomID[k] == RTC_INVALID_GEOMETRY_ID) continue;
          PixelHit& h = hits[static_cast<size_t>(y) * width + x];
          h.primID = packet.hit.primID[k];
          h.u = packet.hit.u[k];
          h.v = packet.hit.v[k];
          h.t = rays[k].tNear + packet.ray.tfar[k];
        }
      } else {
        for (int k = 0; k < 16; ++k) {
          int x, y;
          if (!block.pixel(k, x, y)) continue;
          PixelRay r = pixelRay(camera, x + 0.5, y + 0.5);
          RTCRayHit rayhit;
          setRay(rayhit.ray, r);
          rayhit.hit.geomID = RTC_INVALID_GEOMETRY_ID;
          rayhit.hit.primID = RTC_INVALID_GEOMETRY_ID;
          rtcIntersect1(scene, &context, &rayhit);
          if (rayhit.hit.geomID == RTC_INVALID_GEOMETRY_ID) continue;
          PixelHit& h = hits[static_cast<size_t>(y) * width + x];
          h.primID = rayhit.hit.primID;
          h.u = rayhit.hit.u;
          h.v = rayhit.hit.v;
          h.t = r.tNear + rayhit.ray.tfar;
        }
      }
    }
  });
  return hits;
}

Mask castCoverage(RTCScene scene, const Camera& camera, RayPacking packing,
                  const CancelToken& cancel) {
  const int width = camera.width(), height = camera.height();
  Mask mask(width, height);
  forEachBand(height, cancel, [&](int y0, int y1) {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    for (int x0 = 0; x0 < width; x0 += kBlock) {
      Block block{x0, y0, width, y1};
      if (packing == RayPacking::Packet16) {
        alignas(64) int valid[16];
        alignas(64) RTCRay16 packet;
        for (int k = 0; k < 16; ++k) {
          int x, y;
          valid[k] = block.pixel(k, x, y) ? -1 : 0;
          setLane(packet, k,
                  pixelRay(camera, valid[k] ? x + 0.5 : x0 + 0.5, valid[k] ? y + 0.5 : y0 + 0.5));
        }
        rtcOccluded16(valid, scene, &context, &packet);
        for (int k = 0; k < 16; ++k) {
          int x, y;
          // An occlusion ray that hit something comes back with tfar = -inf.
          if (block.pixel(k, x, y) && packet.tfar[k] < 0.0f) mask.at(x, y) = 1;
        }
      } else {
        for (int k = 0; k < 16; ++k) {
          int x, y;
          if (!block.pixel(k, x, y)) continue;
          RTCRay ray;
          setRay(ray, pixelRay(camera, x + 0.5, y + 0.5));
          rtcOccluded1(scene, &context, &ray);
          if (ray.tfar < 0.0f) mask.at(x, y) = 1;
        }
      }
    }
  });
  return mask;
}

namespace {

// Occlusion rays through up to 16 image-plane points of `camera` at once; bit k of the result is
// set when ray k hit anything.
uint32_t occludedLanes(RTCScene scene, const Camera& camera, const Vec2* points, int count,
                       RTCIntersectContext& context) {
  alignas(64) int valid[16];
  alignas(64) RTCRay16 packet;
  for (int k = 0; k < 16; ++k) {
    valid[k] = k < count ? -1 : 0;
    Vec2 p = points[k < count ? k : 0];
    setLane(packet, k, pixelRay(camera, p.x, p.y));
  }
  rtcOccluded16(valid, scene, &context, &packet);
  uint32_t hits = 0;
  for (int k = 0; k < count; ++k) {
    if (packet.tfar[k] < 0.0f) hits |= 1u << k;  // an occluded ray comes back with tfar = -inf
  }
  return hits;
}

}  // namespace

void castClosestHitsAt(RTCScene scene, const Camera& camera, const std::vector<Vec2>& points,
                       std::vector<PixelHit>& hits, const CancelToken& cancel) {
  hits.assign(points.size(), PixelHit{});
  forEachChunk(
      points.size(), 256, cancel, [&](size_t begin, size_t end, RTCIntersectContext& context) {
        for (size_t i = begin; i < end; ++i) {
          const PixelRay ray = pixelRay(camera, points[i].x, points[i].y);
          RTCRayHit rayhit;
          setRay(rayhit.ray, ray);
          rayhit.hit.geomID = RTC_INVALID_GEOMETRY_ID;
          rayhit.hit.primID = RTC_INVALID_GEOMETRY_ID;
          rtcIntersect1(scene, &context, &rayhit);
          if (rayhit.hit.geomID == RTC_INVALID_GEOMETRY_ID) continue;
          hits[i] = {rayhit.hit.primID, rayhit.hit.u, rayhit.hit.v, ray.tNear + rayhit.ray.tfar};
        }
      });
}

void castCoverageAt(RTCScene scene, const Camera& camera, const std::vector<Vec2>& points,
                    std::vector<char>& covered, const CancelToken& cancel) {
  covered.assign(points.size(), 0);
  const size_t packets = (points.size() + 15) / 16;
  forEachChunk(packets, 64, cancel, [&](size_t begin, size_t end, RTCIntersectContext& context) {
    for (size_t p = begin; p < end; ++p) {
      const size_t first = 16 * p;
      const int count = static_cast<int>(std::min<size_t>(16, points.size() - first));
      uint32_t hits = occludedLanes(scene, camera, points.data() + first, count, context);
      for (int k = 0; k < count; ++k) covered[first + k] = (hits >> k) & 1;
    }
  });
}

Mask castCoverageRefined(RTCScene scene, const Camera& camera, int supersample,
                         const std::vector<char>& refine, const std::vector<char>& coarse,
                         const CancelToken& cancel) {
  const int width = camera.width(), height = camera.height(), s = supersample;
  Mask mask = maskOnHugePages(width * s, height * s);
  forEachBand(height, cancel, [&](int y0, int y1) {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    std::vector<Vec2> samples(static_cast<size_t>(s) * s);
    for (int y = y0; y < y1; ++y) {
      for (int x = 0; x < width; ++x) {
        const size_t pixel = static_cast<size_t>(y) * width + x;
        if (!refine[pixel]) {
          if (!coarse[pixel]) continue;
          for (int j = 0; j < s; ++j) {
            std::fill_n(&mask.at(x * s, y * s + j), s, uint8_t{1});
          }
          continue;
        }
        // The block's sample centres, in output pixels, cast 16 at a time.
        for (int j = 0; j < s; ++j) {
          for (int i = 0; i < s; ++i) samples[j * s + i] = {x + (i + 0.5) / s, y + (j + 0.5) / s};
        }
        for (int first = 0; first < s * s; first += 16) {
          int count = std::min(16, s * s - first);
          uint32_t hits = occludedLanes(scene, camera, &samples[first], count, context);
          for (int k = 0; k < count; ++k) {
            int i = (first + k) % s, j = (first + k) / s;
            if ((hits >> k) & 1) mask.at(x * s + i, y * s + j) = 1;
          }
        }
      }
    }
  });
  return mask;
}

}  // namespace limn::render::oracle
