#include "render/oracle/reference_passes.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>

#include "render/oracle/ray_caster.h"

namespace limn::render::oracle {

std::vector<char> pixelsToRefine(const std::vector<char>& covered, std::vector<char> refine,
                                 int width, int height, const Image* hint, int s) {
  constexpr uint8_t kSomeUncovered = 1, kSomeCovered = 2;
  tbb::parallel_for(tbb::blocked_range<int>(0, height, 16), [&](const tbb::blocked_range<int>& r) {
    std::vector<uint8_t> hintBlocks(width);  // what each block of the hint holds, row by row
    for (int y = r.begin(); y < r.end(); ++y) {
      if (hint) {
        std::fill(hintBlocks.begin(), hintBlocks.end(), uint8_t{0});
        for (int j = y * s; j < (y + 1) * s; ++j) {
          const float* row = &hint->pixels[static_cast<size_t>(j) * hint->width];
          for (int x = 0; x < width; ++x) {
            uint8_t seen = 0;
            for (int i = x * s; i < (x + 1) * s; ++i)
              seen |= row[i] > 0.5f ? kSomeCovered : kSomeUncovered;
            hintBlocks[x] |= seen;
          }
        }
      }
      for (int x = 0; x < width; ++x) {
        const size_t p = static_cast<size_t>(y) * width + x;
        if (refine[p]) continue;
        bool differs = hint && hintBlocks[x] != (covered[p] ? kSomeCovered : kSomeUncovered);
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

metrics::CoverageQuery coverageQuery(RTCScene scene, const Camera& camera,
                                     const CancelToken& cancel) {
  return [scene, &camera, &cancel](const std::vector<Vec2>& points, std::vector<char>& covered) {
    castCoverageAt(scene, camera, points, covered, cancel);
  };
}

}  // namespace limn::render::oracle
