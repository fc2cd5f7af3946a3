// What both references (the limit surface's and the implicit surface's) do the same way: the
// shaded passes written pixel by pixel, the choice of pixels whose supersampled mask is cast in
// full, and a coverage query on a scene for the outline search.
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <array>
#include <cstdint>
#include <vector>

#include "render/core/camera.h"
#include "render/core/cancel.h"
#include "render/core/huge_pages.h"
#include "render/core/image.h"
#include "render/core/passes.h"
#include "render/core/shading.h"
#include "render/metrics/outline.h"
#include "render/oracle/embree_device.h"
#include "render/oracle/ray_caster.h"
#include "render/oracle/reference.h"
#include "render/oracle/surface_hit.h"

namespace limn::render::oracle {

// The output images of the selected passes, filled pixel by pixel.
struct PassImages {
  Image* color = nullptr;
  Image* mask = nullptr;
  Image* depth = nullptr;
  Image* normal = nullptr;

  PassImages(ImageSet& set, const PassSelection& passes, int width, int height) {
    if (passes.color || passes.wireframe) {
      color = &set.passes[pass::kColor];
      *color = imageOnHugePages(width, height, 4);
      for (size_t i = 0; i < color->pixels.size(); i += 4) {
        for (int c = 0; c < 3; ++c) color->pixels[i + c] = shading::kBackground[c];
        color->pixels[i + 3] = 0.0f;
      }
    }
    if (passes.mask) mask = &(set.passes[pass::kMask] = imageOnHugePages(width, height, 1));
    if (passes.depth) depth = &(set.passes[pass::kDepth] = imageOnHugePages(width, height, 1));
    if (passes.normal) normal = &(set.passes[pass::kNormal] = imageOnHugePages(width, height, 3));
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
      float rgb[3];
      shadeHit(hit, camera, rgb);
      for (int c = 0; c < 3; ++c) color->at(x, y, c) = rgb[c];
      color->at(x, y, 3) = 1.0f;
    }
  }

  // shading::shade() at a hit, seen from the camera.
  static void shadeHit(const SurfaceHit& hit, const Camera& camera, float rgb[3]) {
    const Vec3 toEye = camera.projection() == Projection::Perspective
                           ? normalize(camera.eye() - hit.position)
                           : -camera.forward();
    shading::shade(hit.normal, toEye, rgb);
  }
};

// Pixels (row-major indices) where the picture changes abruptly: a hit next to a miss among its
// 8 neighbours, or two hits more than 5% apart along their rays (one surface over another).
std::vector<int> edgePixels(const std::vector<PixelHit>& hits, int width, int height);

// The colour pass anti-aliased as the rasteriser's multisampling resolves it (passes.antialias,
// `samples` its sample positions within the pixel): the pixels of edgePixels() become the mean
// of one ray per sample, each shaded at surfaceAt(ray, hit) (the ray's hit on the surface, from
// its hit on the scene) or the background with alpha 0 where it misses. Elsewhere a pixel keeps
// its centre's colour: inside one triangle a multisampled pixel is shaded once, at its centre.
template <typename SurfaceAt>
void antialiasEdges(RTCScene scene, const Camera& camera, const std::vector<PixelHit>& hits,
                    const std::vector<std::array<float, 2>>& samples, const CancelToken& cancel,
                    SurfaceAt surfaceAt, Image& color, ReferenceStats& stats) {
  const int width = camera.width();
  const std::vector<int> edges = edgePixels(hits, width, camera.height());
  const size_t n = samples.size();
  std::vector<Vec2> points;
  points.reserve(edges.size() * n);
  for (int p : edges) {
    for (const auto& s : samples) points.push_back({p % width + s[0], p / width + s[1]});
  }
  std::vector<PixelHit> sampleHits;
  castClosestHitsAt(scene, camera, points, sampleHits, cancel);
  stats.raysCast += points.size();
  tbb::parallel_for(tbb::blocked_range<size_t>(0, edges.size(), 64),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t e = r.begin(); e < r.end(); ++e) {
                        float sum[4] = {0, 0, 0, 0};
                        for (size_t k = e * n; k < (e + 1) * n; ++k) {
                          float rgb[3];
                          const float* value = shading::kBackground;
                          if (sampleHits[k].hit()) {
                            const PixelRay ray = pixelRay(camera, points[k].x, points[k].y);
                            PassImages::shadeHit(surfaceAt(ray, sampleHits[k]), camera, rgb);
                            value = rgb;
                            sum[3] += 1.0f;
                          }
                          for (int c = 0; c < 3; ++c) sum[c] += value[c];
                        }
                        const int x = edges[e] % width, y = edges[e] / width;
                        for (int c = 0; c < 4; ++c) color.at(x, y, c) = sum[c] / n;
                      }
                    });
  cancel.check();
}

// Output pixels whose S x S samples must all be cast (see renderReference in reference.h):
// `refine` (outline candidates known beforehand), those with an 8-neighbour of other coverage,
// and those where the hint's block (oracle::maskBlocks) is mixed or disagrees with the pixel.
std::vector<char> pixelsToRefine(const std::vector<char>& covered, std::vector<char> refine,
                                 int width, int height, const std::vector<uint8_t>* hint);
// The same with the hint a mask at `s` times the size (ignored when it is not).
std::vector<char> pixelsToRefine(const std::vector<char>& covered, std::vector<char> refine,
                                 int width, int height, const Mask* hint, int s);

// The supersampled mask of `scene` at S = s, S x S rays only in the pixels that need them
// (result.refinedPixels): `candidates` (outline candidates known beforehand; may be empty),
// pixels of mixed coverage around them in `hits`, and where options' hint (a mask or its blocks)
// says. Fills result.images.supersampledMask, refinedPixels and the ray counts.
void castSupersampledMask(RTCScene scene, const Camera& camera, const std::vector<PixelHit>& hits,
                          int s, std::vector<char> candidates, const ReferenceOptions& options,
                          const CancelToken& cancel, ReferenceResult& result);

// The reference's wireframe pass when one was asked for: its colour (the exact `surface` has no
// edges to draw), with a warning that says so; the colour pass itself stays only if asked for.
void colorAsWireframe(const PassSelection& passes, const char* surface, ReferenceResult& result);

// Coverage at image-plane points by occlusion rays into `scene`.
metrics::CoverageQuery coverageQuery(RTCScene scene, const Camera& camera,
                                     const CancelToken& cancel);

}  // namespace limn::render::oracle
