// The two passes of the exact Euclidean distance transform (Felzenszwalb & Huttenlocher,
// "Distance Transforms of Sampled Functions"), kept apart so callers can stop half-way.
//
// Pass 1 (ColumnDistances) gives every pixel the distance to the nearest feature in its own
// column (for a binary image that is what the 1D transform of the first dimension computes).
// Pass 2 (RowEnvelope) takes one row of those, builds the lower envelope of the parabolas
// (x - q)^2 + g(q)^2 and reads the exact squared 2D distance off it, left to right.
// squaredDistanceTransform() in metrics.h runs both over the whole image; the silhouette
// metric runs pass 2 only on rows where it needs answers, which on a sparse contour saves most
// of the second pass.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "render/core/cancel.h"

namespace limn::render::metrics {

// Pass 1: per-column distance (in pixels) from each pixel to the nearest feature pixel of its
// column; columns without any feature hold `height` (noFeature()). Distances are 16-bit to
// halve the memory traffic, so images may be at most kMaxSide pixels tall. Runs in parallel
// over column stripes. One instance can be recomputed for several feature sets of the same
// size, which saves allocating (and page-faulting) its buffer again.
class ColumnDistances {
 public:
  static constexpr int kMaxSide = 65535;

  // Throws std::invalid_argument when height exceeds kMaxSide.
  ColumnDistances(int width, int height);

  // `pixels` is row-major, width x height bytes; a pixel is a feature when (byte & featureBits)
  // is non-zero, so one byte can carry flags for several feature sets.
  // `cancel` is checked per stripe of columns.
  void compute(const uint8_t* pixels, uint8_t featureBits,
               const CancelToken& cancel = CancelToken{});

  int width() const { return width_; }
  int height() const { return height_; }
  const uint16_t* row(int y) const {
    return distances_.get() + static_cast<size_t>(y) * static_cast<size_t>(width_);
  }
  bool noFeature(uint16_t g) const { return g >= height_; }

 private:
  int width_, height_;
  // Left uninitialised until compute(): its parallel first touch is cheaper than a serial fill.
  std::unique_ptr<uint16_t[]> distances_;
};

// Pass 2 for one row: the lower envelope of the parabolas rooted at the row's columns that have
// a feature. Reusable across rows (it keeps its buffers) but not shared between threads.
class RowEnvelope {
 public:
  // Builds the envelope of row y. Returns false when no column has a feature (then the whole
  // image has none and every distance is infinite).
  bool build(const ColumnDistances& columns, int y);

  // Squared distance from (x, y) to the nearest feature. Calls must come with x increasing
  // after each build() (the read-out walks the envelope once).
  int64_t squaredDistanceAt(int x);

 private:
  std::vector<int32_t> roots_;      // columns whose parabola is part of the envelope
  std::vector<int64_t> heights_;    // their g^2
  std::vector<double> boundaries_;  // boundaries_[k]: where parabola k starts to be lowest
  int count_ = 0;
  int cursor_ = 0;
};

}  // namespace limn::render::metrics
