// RayCaster: casts the rays of every pixel centre of a camera into an Embree scene, on all
// threads, in bands of rows, and hands back closest hits or coverage.
//
// Rays follow camera.h: pixel (i, j) is traced through (i + 0.5, j + 0.5), row 0 at the top.
// They are clipped to the camera's [near, far] depth range, as the rasteriser clips, so the two
// renderers see the same part of the surface. Each band sets FTZ/DAZ (Embree's requirement) and
// checks the cancel token first; a cancelled cast throws Cancelled after the bands stop.
#pragma once

#include <embree3/rtcore.h>

#include <cstdint>
#include <vector>

#include "render/core/camera.h"
#include "render/core/cancel.h"
#include "render/core/mask.h"

namespace limn::render::oracle {

// How rays are handed to Embree. Packet16 (4 x 4 pixel blocks) is the default: on primary rays
// it is faster than single rays (see oracle_test's timing output); Single stays for comparison.
enum class RayPacking { Single, Packet16 };

// A pixel's ray in double precision, clipped to the camera's depth range: points o + t d with
// t in [tNear, tFar].
struct PixelRay {
  Vec3 origin;
  Vec3 direction;  // unit
  double tNear = 0, tFar = 0;
};
PixelRay pixelRay(const Camera& camera, double px, double py);

struct PixelHit {
  uint32_t primID = RTC_INVALID_GEOMETRY_ID;  // RTC_INVALID_GEOMETRY_ID: the ray missed
  float u = 0, v = 0;                         // Embree's hit coordinates on the primitive
  double t = 0;                               // along the pixel's PixelRay
  bool hit() const { return primID != RTC_INVALID_GEOMETRY_ID; }
};

// Closest hits of all pixels of `camera`, row-major (width * height).
std::vector<PixelHit> castClosestHits(RTCScene scene, const Camera& camera, RayPacking packing,
                                      const CancelToken& cancel);

// Closest hits at arbitrary image-plane points of `camera` (output pixels, x right, y down), one
// per point, t along pixelRay(camera, point); all threads. For the few rays of anti-aliased
// outline pixels: single rays, not packets.
void castClosestHitsAt(RTCScene scene, const Camera& camera, const std::vector<Vec2>& points,
                       std::vector<PixelHit>& hits, const CancelToken& cancel);

// Coverage of all pixels of `camera`: 1 where the ray hits anything, else 0 (occlusion rays,
// cheaper than closest hits).
Mask castCoverage(RTCScene scene, const Camera& camera, RayPacking packing,
                  const CancelToken& cancel);

// Coverage at arbitrary image-plane points of `camera` (output pixels, x right, y down): 1 where
// the ray through the point hits anything. covered is resized to points.size(). All threads;
// rays go 16 to a packet in the order given, so neighbouring points should come together.
void castCoverageAt(RTCScene scene, const Camera& camera, const std::vector<Vec2>& points,
                    std::vector<char>& covered, const CancelToken& cancel);

// The coverage mask at `supersample` times the camera's size, with rays only where they can
// change it: output pixels marked in `refine` (row-major, width * height) get all S x S of their
// samples cast; the others copy `coarse`'s value (1 covered / 0 not, per output pixel) into
// their whole block.
Mask castCoverageRefined(RTCScene scene, const Camera& camera, int supersample,
                         const std::vector<char>& refine, const std::vector<char>& coarse,
                         const CancelToken& cancel);

}  // namespace limn::render::oracle
