#include "render/oracle/reference_passes.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "render/oracle/ray_caster.h"
#include "render/oracle/reference.h"

namespace limn::render::oracle {

std::vector<uint8_t> maskBlocks(const Mask& supersampledMask, int s) {
  const int width = supersampledMask.width / s, height = supersampledMask.height / s;
  std::vector<uint8_t> blocks(static_cast<size_t>(width) * height, 0);
  tbb::parallel_for(tbb::blocked_range<int>(0, height, 16), [&](const tbb::blocked_range<int>& r) {
    for (int y = r.begin(); y < r.end(); ++y) {
      uint8_t* out = &blocks[static_cast<size_t>(y) * width];
      for (int j = y * s; j < (y + 1) * s; ++j) {
        const uint8_t* row =
            supersampledMask.covered.data() + static_cast<size_t>(j) * supersampledMask.width;
        for (int x = 0; x < width; ++x) {
          uint8_t seen = 0;
          for (int i = x * s; i < (x + 1) * s; ++i)
            seen |= row[i] ? kBlockCovered : kBlockUncovered;
          out[x] |= seen;
        }
      }
    }
  });
  return blocks;
}

void mergeMaskBlocks(std::vector<uint8_t>& into, const std::vector<uint8_t>& blocks) {
  if (into.empty()) {
    into = blocks;
    return;
  }
  if (into.size() != blocks.size()) throw std::invalid_argument("mask blocks of different sizes");
  for (size_t p = 0; p < into.size(); ++p) into[p] |= blocks[p];
}

std::vector<char> pixelsToRefine(const std::vector<char>& covered, std::vector<char> refine,
                                 int width, int height, const std::vector<uint8_t>* hint) {
  if (hint && hint->size() != covered.size()) hint = nullptr;
  tbb::parallel_for(tbb::blocked_range<int>(0, height, 16), [&](const tbb::blocked_range<int>& r) {
    for (int y = r.begin(); y < r.end(); ++y) {
      for (int x = 0; x < width; ++x) {
        const size_t p = static_cast<size_t>(y) * width + x;
        if (refine[p]) continue;
        bool differs = hint && (*hint)[p] != (covered[p] ? kBlockCovered : kBlockUncovered);
        for (int dy = -1; dy <= 1 && !differs; ++dy) {
          for (int dx = -1; dx <= 1 && !differs; ++dx) {
            int nx = x + dx, ny = y + dy;
            if (nx < 0 || ny < 0 || nx >= width || ny >= height) continue;
            differs = covered[static_cast<size_t>(ny) * width + nx] != covered[p];
          }
        }
        refine[p] = differs;
      }
    }
  });
  return refine;
}

std::vector<char> pixelsToRefine(const std::vector<char>& covered, std::vector<char> refine,
                                 int width, int height, const Mask* hint, int s) {
  if (!hint || hint->width != width * s || hint->height != height * s) {
    return pixelsToRefine(covered, std::move(refine), width, height, nullptr);
  }
  const std::vector<uint8_t> blocks = maskBlocks(*hint, s);
  return pixelsToRefine(covered, std::move(refine), width, height, &blocks);
}

void castSupersampledMask(RTCScene scene, const Camera& camera, const std::vector<PixelHit>& hits,
                          int s, std::vector<char> candidates, const ReferenceOptions& options,
                          const CancelToken& cancel, ReferenceResult& result) {
  const int width = camera.width(), height = camera.height();
  std::vector<char> coverage(hits.size());
  for (size_t p = 0; p < hits.size(); ++p) coverage[p] = hits[p].hit();
  if (candidates.size() != coverage.size()) candidates.assign(coverage.size(), 0);
  result.refinedPixels =
      options.hintBlocks
          ? pixelsToRefine(coverage, std::move(candidates), width, height, options.hintBlocks)
          : pixelsToRefine(coverage, std::move(candidates), width, height, options.maskHint, s);
  size_t refined = 0;
  for (char r : result.refinedPixels) refined += r != 0;
  result.stats.refinedPixels = refined;
  result.stats.raysCast += refined * s * s;
  result.images.supersampledMask =
      castCoverageRefined(scene, camera, s, result.refinedPixels, coverage, cancel);
  result.images.supersample = s;
}

std::vector<int> edgePixels(const std::vector<PixelHit>& hits, int width, int height) {
  constexpr double kDepthJump = 0.05;
  // Rows in parallel, joined in row order: the same list as one pass over the image.
  std::vector<std::vector<int>> rowEdges(height);
  tbb::parallel_for(tbb::blocked_range<int>(0, height, 16), [&](const tbb::blocked_range<int>& r) {
    for (int y = r.begin(); y < r.end(); ++y) {
      for (int x = 0; x < width; ++x) {
        const PixelHit& h = hits[static_cast<size_t>(y) * width + x];
        bool edge = false;
        for (int dy = -1; dy <= 1 && !edge; ++dy) {
          for (int dx = -1; dx <= 1 && !edge; ++dx) {
            const int u = x + dx, v = y + dy;
            if (u < 0 || v < 0 || u >= width || v >= height) continue;
            const PixelHit& g = hits[static_cast<size_t>(v) * width + u];
            edge = g.hit() != h.hit() ||
                   (h.hit() && std::fabs(g.t - h.t) > kDepthJump * std::min(g.t, h.t));
          }
        }
        if (edge) rowEdges[y].push_back(y * width + x);
      }
    }
  });
  std::vector<int> edges;
  for (const std::vector<int>& row : rowEdges) edges.insert(edges.end(), row.begin(), row.end());
  return edges;
}

void colorAsWireframe(const PassSelection& passes, const char* surface, ReferenceResult& result) {
  if (!passes.wireframe) return;
  result.images.passes[pass::kWireframe] = result.images.passes[pass::kColor];
  if (!passes.color) result.images.passes.erase(pass::kColor);
  result.warnings.push_back(std::string("reference wireframe: the ") + surface +
                            " has no edges; the pass is the shaded color");
}

metrics::CoverageQuery coverageQuery(RTCScene scene, const Camera& camera,
                                     const CancelToken& cancel) {
  return [scene, &camera, &cancel](const std::vector<Vec2>& points, std::vector<char>& covered) {
    castCoverageAt(scene, camera, points, covered, cancel);
  };
}

}  // namespace limn::render::oracle
