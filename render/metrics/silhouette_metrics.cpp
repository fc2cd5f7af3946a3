// compareSilhouettes(): Hausdorff and mean contour distance, IoU and majority mismatch of two
// supersampled coverage masks, as DESIGN.md's "Metrics, defined" says.
//
// Speed matters here (a 1024^2 output at S = 4 is 16.7 million pixels a mask), so the work is
// arranged as few passes over memory as possible:
//   1. one pass over both byte masks gives a byte per pixel with four flags (covered in A,
//      in B, contour of A, of B) and counts IoU and the majority mismatch on the way;
//   2. per direction, each contour pixel's nearest pixel of the other contour, searched in the
//      rows around it among the other contour's pixels listed per row (exact, and at 4096^2 a
//      few milliseconds where a whole-image transform took 100-250 ms); where some pixel has
//      none within 64 rows (a rendering far off), the exact distance transform: a column pass
//      over the other contour, then row envelopes only on the rows holding pixels to measure;
//   3. with the renderings' geometry, the few contour pixels more than a pixel from the other
//      contour are measured again to the other's triangles (coverage_distance.h).
// Every pass runs in parallel over rows or column stripes; per-row partial results are summed
// in row order afterwards, so the numbers do not depend on the thread count.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "render/core/huge_pages.h"
#include "render/metrics/coverage_distance.h"
#include "render/metrics/distance_transform.h"
#include "render/metrics/metrics.h"

namespace limn::render::metrics {

namespace {

constexpr int kRowGrain = 16;

// Flags of one pixel in the shared byte image.
constexpr uint8_t kCoveredA = 1, kCoveredB = 2, kContourA = 4, kContourB = 8;

// What one pass over both masks learns: a byte of flags per pixel, which rows hold contour
// pixels, and the coverage counts.
struct Classified {
  std::unique_ptr<uint8_t[]> pixels;  // kCoveredA | kCoveredB | kContourA | kContourB
  std::vector<uint8_t> rowContours;   // per row: kContourA | kContourB if any pixel has it
  // Per row, the columns of its contour pixels of A and of B, ascending (the contours are a
  // small part of the image: the distances are searched among these lists first).
  std::vector<std::vector<int32_t>> columnsA, columnsB;
  double iou = 1;
  long mismatchPx = 0;
};

// Coverage bits (value nonzero) of one row of both masks; rows outside the image are uncovered.
void coverRow(const Mask& a, const Mask& b, int y, uint8_t* out) {
  const size_t w = static_cast<size_t>(a.width);
  if (y < 0 || y >= a.height) {
    std::fill(out, out + w, uint8_t{0});
    return;
  }
  const uint8_t* ra = a.covered.data() + static_cast<size_t>(y) * w;
  const uint8_t* rb = b.covered.data() + static_cast<size_t>(y) * w;
  for (size_t x = 0; x < w; ++x) {
    out[x] = static_cast<uint8_t>((ra[x] ? kCoveredA : 0) | (rb[x] ? kCoveredB : 0));
  }
}

// The columns of one row's contour pixels of A and of B.
void listContourColumns(const uint8_t* row, size_t width, std::vector<int32_t>& a,
                        std::vector<int32_t>& b) {
  for (size_t x = 0; x < width; ++x) {
    if (row[x] & kContourA) a.push_back(static_cast<int32_t>(x));
    if (row[x] & kContourB) b.push_back(static_cast<int32_t>(x));
  }
}

// Flags, IoU and majority mismatch in one pass. Contour pixels are covered pixels with an
// uncovered 4-neighbour; outside the image counts as uncovered, so a shape touching the border
// has its contour there. Tasks own whole bands of S rows (one output row each) and keep the
// coverage of three rows in a ring, so each mask byte is read about once and no thread reads
// flags another writes.
Classified classify(const Mask& a, const Mask& b, int s, const CancelToken& cancel) {
  const int width = a.width, height = a.height;
  const int outWidth = width / s, outHeight = height / s;
  const size_t w = static_cast<size_t>(width);
  const int majority = s * s / 2;  // an output pixel is covered when more than half its block is
  Classified result;
  result.pixels.reset(new uint8_t[w * static_cast<size_t>(height)]);
  adviseHugePages(result.pixels.get(), w * static_cast<size_t>(height));
  result.rowContours.assign(height, 0);
  result.columnsA.resize(height);
  result.columnsB.resize(height);
  std::vector<long> bandBoth(outHeight, 0), bandEither(outHeight, 0), bandMismatch(outHeight, 0);

  const int bandGrain = std::max(1, kRowGrain / s);
  tbb::parallel_for(
      tbb::blocked_range<int>(0, outHeight, bandGrain), [&](const tbb::blocked_range<int>& bands) {
        cancel.check();
        std::vector<uint8_t> ring(3 * (w + 2), 0);  // one uncovered pixel either side of each row
        uint8_t* rows[3] = {ring.data() + 1, ring.data() + w + 3, ring.data() + 2 * w + 5};
        std::vector<int> countA(outWidth), countB(outWidth);
        const int y0 = bands.begin() * s;
        coverRow(a, b, y0 - 1, rows[0]);
        coverRow(a, b, y0, rows[1]);
        for (int oy = bands.begin(); oy < bands.end(); ++oy) {
          std::fill(countA.begin(), countA.end(), 0);
          std::fill(countB.begin(), countB.end(), 0);
          long both = 0, either = 0;
          for (int y = oy * s; y < (oy + 1) * s; ++y) {
            coverRow(a, b, y + 1, rows[2]);
            const uint8_t *up = rows[0], *here = rows[1], *down = rows[2];
            uint8_t* out = result.pixels.get() + static_cast<size_t>(y) * w;
            uint8_t rowAny = 0;
            // The rows have one uncovered pixel either side: left[x] is here[x - 1] without
            // an index that wraps below zero.
            const uint8_t *left = here - 1, *right = here + 1;
            for (size_t x = 0; x < w; ++x) {
              // Bits set where all four neighbours are covered too.
              const uint8_t inside = here[x] & up[x] & down[x] & left[x] & right[x];
              const uint8_t contour = static_cast<uint8_t>((here[x] & ~inside) << 2);
              out[x] = here[x] | contour;
              rowAny |= contour;
              both += here[x] == (kCoveredA | kCoveredB);
              either += here[x] != 0;
            }
            result.rowContours[y] = rowAny;
            if (rowAny) listContourColumns(out, w, result.columnsA[y], result.columnsB[y]);
            for (int ox = 0; ox < outWidth; ++ox) {
              const uint8_t* block = here + static_cast<size_t>(ox) * s;
              int ca = 0, cb = 0;
              for (int k = 0; k < s; ++k) {
                ca += block[k] & kCoveredA;
                cb += (block[k] & kCoveredB) >> 1;
              }
              countA[ox] += ca;
              countB[ox] += cb;
            }
            std::rotate(rows, rows + 1, rows + 3);
          }
          long mismatched = 0;
          for (int ox = 0; ox < outWidth; ++ox) {
            mismatched += (countA[ox] > majority) != (countB[ox] > majority);
          }
          bandBoth[oy] = both;
          bandEither[oy] = either;
          bandMismatch[oy] = mismatched;
        }
      });

  long both = 0, either = 0;
  for (int oy = 0; oy < outHeight; ++oy) {
    both += bandBoth[oy];
    either += bandEither[oy];
    result.mismatchPx += bandMismatch[oy];
  }
  result.iou = either == 0 ? 1.0 : static_cast<double>(both) / static_cast<double>(either);
  return result;
}

struct DirectedDistances {
  double max = 0, sum = 0;  // mask pixels
  long count = 0;
};

// Contour pixels further than this (squared, mask pixels) from the other contour are measured
// again on the other's geometry when it can be (coverage_distance.h); nearer ones cannot gain.
constexpr int64_t kRemeasureSquared = 2;

// A contour pixel to measure again, and its sampled distance (mask pixels).
struct Remeasure {
  int x, y;
  double distance;
};

using ContourColumns = std::vector<std::vector<int32_t>>;  // per row, ascending

// Squared distances of one row's contour pixels to the other contour, read off the whole-image
// distance transform of the other contour (its column pass `to`, and a row envelope).
class EnvelopeRows {
 public:
  explicit EnvelopeRows(const ColumnDistances& to) : to_(to) {}
  bool operator()(int y, const std::vector<int32_t>& xs, std::vector<int64_t>& d2) {
    envelope_.build(to_, y);
    for (int32_t x : xs) d2.push_back(envelope_.squaredDistanceAt(x));
    return true;
  }

 private:
  const ColumnDistances& to_;
  RowEnvelope envelope_;
};

// Rows searched either side of a pixel before SearchRows gives up (mask pixels: 16 output pixels
// at S = 4). An approximation's contour is rarely more than a few mask pixels from its
// reference's; a rendering far off is left to the distance transform.
constexpr int kSearchRows = 64;

// The same squared distances found among the other contour's pixels listed per row, searching
// rows outward from the pixel's own until the row distance alone exceeds the best found: exact
// (the same integers as the transform), and at 4096^2 far cheaper than transforming the whole
// mask when the contours lie close together. Returns false when a pixel has no other-contour
// pixel within kSearchRows rows that proves its nearest.
class SearchRows {
 public:
  explicit SearchRows(const ContourColumns& to) : to_(to) {}
  bool operator()(int y, const std::vector<int32_t>& xs, std::vector<int64_t>& d2) {
    for (int32_t x : xs) {
      int64_t best;
      if (!nearest(x, y, best)) return false;
      d2.push_back(best);
    }
    return true;
  }

 private:
  bool nearest(int x, int y, int64_t& best) const {
    const int height = static_cast<int>(to_.size());
    best = std::numeric_limits<int64_t>::max();
    for (int dy = 0; dy <= kSearchRows; ++dy) {
      const int64_t dy2 = static_cast<int64_t>(dy) * dy;
      if (dy2 >= best || (y - dy < 0 && y + dy >= height)) return true;
      if (y - dy >= 0) best = std::min(best, dy2 + nearestInRow(to_[y - dy], x));
      if (dy > 0 && y + dy < height) best = std::min(best, dy2 + nearestInRow(to_[y + dy], x));
    }
    return static_cast<int64_t>(kSearchRows + 1) * (kSearchRows + 1) >= best;
  }

  // Squared column distance from x to the nearest listed column (a large number when none).
  static int64_t nearestInRow(const std::vector<int32_t>& columns, int x) {
    constexpr int64_t kNone = int64_t{1} << 40;
    auto it = std::lower_bound(columns.begin(), columns.end(), x);
    int64_t best = kNone;
    if (it != columns.end()) best = static_cast<int64_t>(*it - x) * (*it - x);
    if (it != columns.begin()) {
      const int64_t dx = x - *(it - 1);
      best = std::min(best, dx * dx);
    }
    return best;
  }

  const ContourColumns& to_;
};

// Distances from every contour pixel listed in `from` to the other contour, their squares given
// row by row by a `Rows` (EnvelopeRows or SearchRows) made per task by `makeRows`; nothing when
// a Rows gives up. With `remeasure`, pixels over kRemeasureSquared are listed there and left out
// of the max (not of the sum). Rows are summed in order: the numbers do not depend on threads.
template <typename MakeRows>
std::optional<DirectedDistances> directedDistances(const ContourColumns& from, MakeRows&& makeRows,
                                                   const CancelToken& cancel,
                                                   std::vector<Remeasure>* remeasure) {
  const int height = static_cast<int>(from.size());
  std::vector<double> rowMax(height, 0.0), rowSum(height, 0.0);
  std::vector<long> rowCount(height, 0);
  std::vector<std::vector<Remeasure>> rowRemeasure(remeasure ? height : 0);
  const int64_t keepBelow = remeasure ? kRemeasureSquared : std::numeric_limits<int64_t>::max();
  std::atomic<bool> gaveUp{false};
  tbb::parallel_for(tbb::blocked_range<int>(0, height, kRowGrain),
                    [&](const tbb::blocked_range<int>& rows) {
                      cancel.check();
                      auto rowsOf = makeRows();
                      std::vector<int64_t> d2;
                      for (int y = rows.begin(); y < rows.end() && !gaveUp; ++y) {
                        const std::vector<int32_t>& xs = from[y];
                        if (xs.empty()) continue;
                        d2.clear();
                        if (!rowsOf(y, xs, d2)) {
                          gaveUp = true;
                          return;
                        }
                        int64_t worst = 0;
                        double sum = 0;
                        for (size_t k = 0; k < xs.size(); ++k) {
                          const double d = std::sqrt(static_cast<double>(d2[k]));
                          if (d2[k] < keepBelow) {
                            worst = std::max(worst, d2[k]);
                          } else {
                            rowRemeasure[y].push_back({xs[k], y, d});
                          }
                          sum += d;
                        }
                        rowMax[y] = std::sqrt(static_cast<double>(worst));
                        rowSum[y] = sum;
                        rowCount[y] = static_cast<long>(xs.size());
                      }
                    });
  if (gaveUp) return std::nullopt;
  DirectedDistances total;
  for (int y = 0; y < height; ++y) {
    total.max = std::max(total.max, rowMax[y]);
    total.sum += rowSum[y];
    total.count += rowCount[y];
    if (remeasure)
      remeasure->insert(remeasure->end(), rowRemeasure[y].begin(), rowRemeasure[y].end());
  }
  return total;
}

// Measures the listed pixels again with `query` (output pixels; see coverage_distance.h) and
// folds their distances, lowered where the geometry is nearer than the samples, into `total`.
void foldRemeasured(const std::vector<Remeasure>& remeasure, double s,
                    const CoverageDistanceQuery& query, DirectedDistances& total) {
  if (remeasure.empty()) return;
  std::vector<Vec2> points;
  std::vector<double> distances;
  points.reserve(remeasure.size());
  distances.reserve(remeasure.size());
  for (const Remeasure& r : remeasure) {
    points.push_back({(r.x + 0.5) / s, (r.y + 0.5) / s});
    distances.push_back(r.distance / s);
  }
  lowerLargestFirst(query, points, distances);
  for (size_t k = 0; k < remeasure.size(); ++k) {
    const double d = std::min(remeasure[k].distance, distances[k] * s);
    total.max = std::max(total.max, d);
    total.sum += d - remeasure[k].distance;
  }
}

// The whole-image distance transform's column pass, made when first needed and reused for the
// other direction (its buffer is the size of the mask).
struct LazyColumns {
  const Classified& flags;
  int width, height;
  std::optional<ColumnDistances> columns;
  const ColumnDistances& of(uint8_t contourBit, const CancelToken& cancel) {
    if (!columns) columns.emplace(width, height);
    columns->compute(flags.pixels.get(), contourBit, cancel);
    return *columns;
  }
};

// The distances from the contour pixels `from` (flag `fromBit`) to the other contour, measured
// again on the other's geometry where `toGeometry` is given. Searched near each pixel first;
// the distance transform where that gives up or `search` asks for it.
DirectedDistances contourDistances(const Classified& flags, uint8_t fromBit, LazyColumns& lazy,
                                   double s, const CoverageDistanceQuery* toGeometry,
                                   ContourSearch search, const CancelToken& cancel) {
  const bool fromA = fromBit == kContourA;
  const ContourColumns& from = fromA ? flags.columnsA : flags.columnsB;
  const ContourColumns& to = fromA ? flags.columnsB : flags.columnsA;
  std::vector<Remeasure> remeasure;
  std::vector<Remeasure>* listed = toGeometry ? &remeasure : nullptr;
  std::optional<DirectedDistances> d;
  if (search == ContourSearch::Nearby) {
    d = directedDistances(
        from, [&] { return SearchRows(to); }, cancel, listed);
  }
  if (!d) {
    remeasure.clear();
    const ColumnDistances& columns = lazy.of(fromA ? kContourB : kContourA, cancel);
    d = directedDistances(
        from, [&] { return EnvelopeRows(columns); }, cancel, listed);
  }
  if (toGeometry) foldRemeasured(remeasure, s, *toGeometry, *d);
  return *d;
}

void checkMasks(const Mask& mask, const Mask& referenceMask, int supersample) {
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
  for (const Mask* m : {&mask, &referenceMask}) {
    if (m->covered.size() != static_cast<size_t>(m->width) * static_cast<size_t>(m->height)) {
      throw std::invalid_argument("compareSilhouettes: a mask must hold one byte per pixel");
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

SilhouetteMetrics compareSilhouettes(const Mask& mask, const Mask& referenceMask, int supersample,
                                     const CancelToken& cancel, const SilhouetteGeometry& geometry,
                                     ContourSearch search) {
  checkMasks(mask, referenceMask, supersample);
  const int width = mask.width, height = mask.height;
  const double s = supersample;

  const Classified flags = classify(mask, referenceMask, supersample, cancel);
  SilhouetteMetrics result;
  result.iou = flags.iou;
  result.mismatchPx = flags.mismatchPx;

  uint8_t anyContour = 0;
  for (uint8_t r : flags.rowContours) anyContour |= r;
  const bool emptyA = !(anyContour & kContourA), emptyB = !(anyContour & kContourB);
  if (emptyA && emptyB) return result;  // nothing drawn in either: distances are 0
  if (emptyA || emptyB) {
    // One image shows the object and the other shows nothing: no distance between contours
    // exists, so both distances report the worst any pair of pixels could be apart, the image
    // diagonal in output pixels.
    result.hausdorffPx = std::hypot(width / s, height / s);
    result.meanPx = result.hausdorffPx;
    return result;
  }

  LazyColumns columns{flags, width, height, std::nullopt};
  const DirectedDistances aToB =
      contourDistances(flags, kContourA, columns, s, geometry.reference, search, cancel);
  const DirectedDistances bToA =
      contourDistances(flags, kContourB, columns, s, geometry.approximation, search, cancel);
  result.hausdorffPx = std::max(aToB.max, bToA.max) / s;
  result.meanPx = (aToB.sum + bToA.sum) / static_cast<double>(aToB.count + bToA.count) / s;
  return result;
}

}  // namespace limn::render::metrics
