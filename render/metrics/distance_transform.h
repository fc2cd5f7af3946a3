// The two passes of the exact Euclidean distance transform (Felzenszwalb & Huttenlocher,
// "Distance Transforms of Sampled Functions"), kept apart so callers can stop half-way.
//
// Pass 1 (ColumnDistances) gives every pixel the distance to the nearest feature in its own
// column. Pass 2 (RowEnvelope) takes one row of those, builds the lower envelope of the
// parabolas (x - q)^2 + g(q)^2 and reads the exact squared 2D distance off it, left to right.
// squaredDistanceTransform() in metrics.h runs both over the whole image; the silhouette
// metric runs pass 2 only on rows where it needs answers, which on a sparse contour is most of
// the saving.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace limn::render::metrics {

// Pass 1: per-column distance (in pixels) from each pixel to the nearest feature pixel of its
// column. `features` is row-major, nonzero = feature. Columns without any feature get values
// >= height (noFeature()). Runs in parallel over column stripes.
class ColumnDistances {
 public:
  ColumnDistances(const std::vector<uint8_t>& features, int width, int height);

  int width() const { return width_; }
  int height() const { return height_; }
  const int32_t* row(int y) const { return distances_.data() + static_cast<size_t>(y) * width_; }
  bool noFeature(int32_t g) const { return g >= height_; }

 private:
  int width_, height_;
  std::vector<int32_t> distances_;
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
  std::vector<int32_t> roots_;       // columns whose parabola is part of the envelope
  std::vector<int64_t> heights_;     // their g^2
  std::vector<double> boundaries_;   // boundaries_[k]: where parabola k starts to be lowest
  int count_ = 0;
  int cursor_ = 0;
};

}  // namespace limn::render::metrics
