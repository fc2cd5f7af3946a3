// compareSilhouettes(): Hausdorff and mean contour distance, IoU and majority mismatch of two
// supersampled coverage masks, as DESIGN.md's "Metrics, defined" says.
//
// Every stage is one pass over the image, parallel over rows or column stripes, with per-row
// partial results summed in row order afterwards so the numbers do not depend on the thread
// count. At 4096 x 4096 the whole comparison takes well under a second on two cores.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "render/metrics/distance_transform.h"
#include "render/metrics/metrics.h"

namespace limn::render::metrics {

namespace {

constexpr int kRowGrain = 16;

template <typename Body>
void forEachRow(int height, Body&& body) {
  tbb::parallel_for(tbb::blocked_range<int>(0, height, kRowGrain),
                    [&](const tbb::blocked_range<int>& rows) {
                      for (int y = rows.begin(); y < rows.end(); ++y) body(y);
                    });
}

// 1 where the mask's value is above one half.
std::vector<uint8_t> coverage(const Image& mask) {
  std::vector<uint8_t> covered(mask.pixels.size());
  const size_t w = static_cast<size_t>(mask.width);
  forEachRow(mask.height, [&](int y) {
    const float* in = mask.pixels.data() + y * w;
    uint8_t* out = covered.data() + y * w;
    for (size_t x = 0; x < w; ++x) out[x] = in[x] > 0.5f ? 1 : 0;
  });
  return covered;
}

// Covered pixels with an uncovered 4-neighbour; outside the image counts as uncovered, so a
// shape touching the border has its contour there.
std::vector<uint8_t> silhouette(const std::vector<uint8_t>& covered, int width, int height) {
  std::vector<uint8_t> contour(covered.size(), 0);
  const size_t w = static_cast<size_t>(width);
  if (w == 0) return contour;
  forEachRow(height, [&](int y) {
    const uint8_t* row = covered.data() + y * w;
    uint8_t* out = contour.data() + y * w;
    if (y == 0 || y == height - 1) {
      std::copy(row, row + w, out);
      return;
    }
    const uint8_t* above = row - w;
    const uint8_t* below = row + w;
    out[0] = row[0];
    out[w - 1] = row[w - 1];
    for (size_t x = 1; x + 1 < w; ++x) {
      out[x] = row[x] & ~(above[x] & below[x] & row[x - 1] & row[x + 1]) & 1;
    }
  });
  return contour;
}

struct DirectedDistances {
  double max = 0, sum = 0;
  long count = 0;
};

// Distances from every pixel of `from` to the nearest feature behind `to`. Only rows holding
// pixels of `from` build their envelope; the caller guarantees `to` has at least one feature.
DirectedDistances directedDistances(const std::vector<uint8_t>& from, const ColumnDistances& to) {
  const int width = to.width(), height = to.height();
  std::vector<double> rowMax(height, 0.0), rowSum(height, 0.0);
  std::vector<long> rowCount(height, 0);
  tbb::parallel_for(tbb::blocked_range<int>(0, height, kRowGrain),
                    [&](const tbb::blocked_range<int>& rows) {
    RowEnvelope envelope;
    for (int y = rows.begin(); y < rows.end(); ++y) {
      const uint8_t* row = from.data() + static_cast<size_t>(y) * width;
      if (std::find(row, row + width, 1) == row + width) continue;
      envelope.build(to, y);
      int64_t worst = 0;
      double sum = 0;
      long count = 0;
      for (int x = 0; x < width; ++x) {
        if (!row[x]) continue;
        const int64_t d2 = envelope.squaredDistanceAt(x);
        worst = std::max(worst, d2);
        sum += std::sqrt(static_cast<double>(d2));
        ++count;
      }
      rowMax[y] = std::sqrt(static_cast<double>(worst));
      rowSum[y] = sum;
      rowCount[y] = count;
    }
  });
  DirectedDistances total;
  for (int y = 0; y < height; ++y) {
    total.max = std::max(total.max, rowMax[y]);
    total.sum += rowSum[y];
    total.count += rowCount[y];
  }
  return total;
}

// Output pixels (S x S blocks) where one mask covers more than half the block and the other
// does not.
long majorityMismatch(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b, int width,
                      int height, int s) {
  const int outWidth = width / s, outHeight = height / s;
  const int majority = s * s / 2;  // covered when strictly more than half the block is
  std::vector<long> rowMismatch(outHeight, 0);
  forEachRow(outHeight, [&](int oy) {
    std::vector<int> countA(outWidth, 0), countB(outWidth, 0);
    for (int y = oy * s; y < (oy + 1) * s; ++y) {
      const uint8_t* ra = a.data() + static_cast<size_t>(y) * width;
      const uint8_t* rb = b.data() + static_cast<size_t>(y) * width;
      for (int x = 0; x < outWidth * s; ++x) {
        countA[x / s] += ra[x];
        countB[x / s] += rb[x];
      }
    }
    long mismatched = 0;
    for (int ox = 0; ox < outWidth; ++ox) {
      mismatched += (countA[ox] > majority) != (countB[ox] > majority);
    }
    rowMismatch[oy] = mismatched;
  });
  long total = 0;
  for (long m : rowMismatch) total += m;
  return total;
}

double intersectionOverUnion(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b,
                             int width, int height) {
  std::vector<long> rowBoth(height, 0), rowEither(height, 0);
  forEachRow(height, [&](int y) {
    const uint8_t* ra = a.data() + static_cast<size_t>(y) * width;
    const uint8_t* rb = b.data() + static_cast<size_t>(y) * width;
    long both = 0, either = 0;
    for (int x = 0; x < width; ++x) {
      both += ra[x] & rb[x];
      either += ra[x] | rb[x];
    }
    rowBoth[y] = both;
    rowEither[y] = either;
  });
  long both = 0, either = 0;
  for (int y = 0; y < height; ++y) {
    both += rowBoth[y];
    either += rowEither[y];
  }
  return either == 0 ? 1.0 : static_cast<double>(both) / static_cast<double>(either);
}

void checkMasks(const Image& mask, const Image& referenceMask, int supersample) {
  if (supersample < 1) {
    throw std::invalid_argument("compareSilhouettes: supersample must be at least 1, got " +
                                std::to_string(supersample));
  }
  if (mask.width != referenceMask.width || mask.height != referenceMask.height) {
    throw std::invalid_argument(
        "compareSilhouettes: masks differ in size: " + std::to_string(mask.width) + "x" +
        std::to_string(mask.height) + " vs " + std::to_string(referenceMask.width) + "x" +
        std::to_string(referenceMask.height));
  }
  for (const Image* m : {&mask, &referenceMask}) {
    if (m->channels != 1 ||
        m->pixels.size() != static_cast<size_t>(m->width) * static_cast<size_t>(m->height)) {
      throw std::invalid_argument("compareSilhouettes: a mask must have exactly one channel");
    }
  }
  if (mask.width % supersample != 0 || mask.height % supersample != 0) {
    throw std::invalid_argument("compareSilhouettes: mask size " + std::to_string(mask.width) +
                                "x" + std::to_string(mask.height) +
                                " is not a multiple of the supersample factor " +
                                std::to_string(supersample));
  }
}

}  // namespace

SilhouetteMetrics compareSilhouettes(const Image& mask, const Image& referenceMask,
                                     int supersample) {
  checkMasks(mask, referenceMask, supersample);
  const int width = mask.width, height = mask.height;
  const double s = supersample;

  const std::vector<uint8_t> coveredA = coverage(mask);
  const std::vector<uint8_t> coveredB = coverage(referenceMask);
  SilhouetteMetrics result;
  result.iou = intersectionOverUnion(coveredA, coveredB, width, height);
  result.mismatchPx = majorityMismatch(coveredA, coveredB, width, height, supersample);

  const std::vector<uint8_t> contourA = silhouette(coveredA, width, height);
  const std::vector<uint8_t> contourB = silhouette(coveredB, width, height);
  const bool emptyA = std::find(contourA.begin(), contourA.end(), 1) == contourA.end();
  const bool emptyB = std::find(contourB.begin(), contourB.end(), 1) == contourB.end();
  if (emptyA && emptyB) return result;  // nothing drawn in either: distances are 0
  if (emptyA || emptyB) {
    // One image shows the object and the other shows nothing: no distance between contours
    // exists, so both distances report the worst any pair of pixels could be apart, the image
    // diagonal in output pixels.
    result.hausdorffPx = std::hypot(width / s, height / s);
    result.meanPx = result.hausdorffPx;
    return result;
  }

  DirectedDistances aToB, bToA;
  {
    const ColumnDistances toB(contourB, width, height);
    aToB = directedDistances(contourA, toB);
  }
  {
    const ColumnDistances toA(contourA, width, height);
    bToA = directedDistances(contourB, toA);
  }
  result.hausdorffPx = std::max(aToB.max, bToA.max) / s;
  result.meanPx = (aToB.sum + bToA.sum) / static_cast<double>(aToB.count + bToA.count) / s;
  return result;
}

}  // namespace limn::render::metrics
