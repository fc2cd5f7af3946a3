// Exact Euclidean distance transform: column pass, row envelopes, and the whole-image
// squaredDistanceTransform() of metrics.h built from the two.
#include "render/metrics/distance_transform.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>

#include "render/core/huge_pages.h"
#include "render/metrics/metrics.h"

namespace limn::render::metrics {

namespace {
// Columns per task of the column pass: wide enough that each row visit reads whole cache lines,
// narrow enough that two cores share a 1024-wide image.
constexpr int kColumnStripe = 256;
constexpr int kRowGrain = 16;
}  // namespace

ColumnDistances::ColumnDistances(int width, int height) : width_(width), height_(height) {
  if (width < 0 || height < 0 || height > kMaxSide) {
    throw std::invalid_argument("distance transform: image height " + std::to_string(height) +
                                " is outside 0.." + std::to_string(kMaxSide));
  }
  const size_t count = static_cast<size_t>(width) * static_cast<size_t>(height);
  distances_.reset(new uint16_t[count]);
  adviseHugePages(distances_.get(), count * sizeof(uint16_t));
}

void ColumnDistances::compute(const uint8_t* pixels, uint8_t featureBits,
                              const CancelToken& cancel) {
  if (width_ == 0 || height_ == 0) return;
  // Rows are walked in order inside a stripe of columns, so memory is read forwards. A column
  // without features saturates at `height`: noFeature().
  const size_t w = static_cast<size_t>(width_);
  const uint16_t none = static_cast<uint16_t>(height_);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, w, kColumnStripe),
                    [&](const tbb::blocked_range<size_t>& stripe) {
                      cancel.check();
                      const size_t x0 = stripe.begin(), x1 = stripe.end();
                      for (size_t x = x0; x < x1; ++x)
                        distances_[x] = (pixels[x] & featureBits) ? 0 : none;
                      for (size_t y = 1; y < static_cast<size_t>(height_); ++y) {
                        const uint8_t* f = pixels + y * w;
                        uint16_t* d = distances_.get() + y * w;
                        const uint16_t* above = d - w;
                        for (size_t x = x0; x < x1; ++x) {
                          // Computed in int: at height 65535, none + 1 does not fit 16 bits.
                          const uint16_t next =
                              static_cast<uint16_t>(std::min<int>(above[x] + 1, none));
                          d[x] = (f[x] & featureBits) ? 0 : next;
                        }
                      }
                      for (size_t y = static_cast<size_t>(height_) - 1; y-- > 0;) {
                        uint16_t* d = distances_.get() + y * w;
                        const uint16_t* below = d + w;
                        for (size_t x = x0; x < x1; ++x) {
                          d[x] = static_cast<uint16_t>(std::min<int>(d[x], below[x] + 1));
                        }
                      }
                    });
}

bool RowEnvelope::build(const ColumnDistances& columns, int y) {
  const int width = columns.width();
  if (static_cast<int>(roots_.size()) < width + 1) {
    roots_.resize(width + 1);
    heights_.resize(width + 1);
    boundaries_.resize(width + 1);
  }
  const uint16_t* g = columns.row(y);
  int k = -1;
  for (int q = 0; q < width; ++q) {
    if (columns.noFeature(g[q])) continue;
    const int64_t fq = static_cast<int64_t>(g[q]) * g[q];
    if (k < 0) {
      k = 0;
      roots_[0] = q;
      heights_[0] = fq;
      boundaries_[0] = -std::numeric_limits<double>::infinity();
      continue;
    }
    // Where the new parabola crosses the top of the envelope; parabolas it hides entirely are
    // dropped. The first one's boundary is -inf, so the loop always stops.
    double s;
    for (;;) {
      const int64_t r = roots_[k];
      s = static_cast<double>((fq + static_cast<int64_t>(q) * q) - (heights_[k] + r * r)) /
          (2.0 * static_cast<double>(q - r));
      if (s > boundaries_[k]) break;
      --k;
    }
    ++k;
    roots_[k] = q;
    heights_[k] = fq;
    boundaries_[k] = s;
  }
  count_ = k + 1;
  cursor_ = 0;
  if (count_ > 0) boundaries_[count_] = std::numeric_limits<double>::infinity();
  return count_ > 0;
}

int64_t RowEnvelope::squaredDistanceAt(int x) {
  while (boundaries_[cursor_ + 1] < x) ++cursor_;
  const int64_t dx = x - roots_[cursor_];
  return dx * dx + heights_[cursor_];
}

std::vector<double> squaredDistanceTransform(const std::vector<bool>& isFeature, int width,
                                             int height) {
  if (width < 0 || height < 0 ||
      isFeature.size() != static_cast<size_t>(width) * static_cast<size_t>(height)) {
    throw std::invalid_argument("squaredDistanceTransform: isFeature has " +
                                std::to_string(isFeature.size()) + " entries for a " +
                                std::to_string(width) + "x" + std::to_string(height) + " image");
  }
  std::vector<uint8_t> features(isFeature.begin(), isFeature.end());
  ColumnDistances columns(width, height);
  columns.compute(features.data(), 1);
  std::vector<double> result(features.size(), std::numeric_limits<double>::infinity());
  tbb::parallel_for(tbb::blocked_range<int>(0, height, kRowGrain),
                    [&](const tbb::blocked_range<int>& rows) {
                      RowEnvelope envelope;
                      for (int y = rows.begin(); y < rows.end(); ++y) {
                        // No feature in this row's envelope means none in the image: leave
                        // +infinity.
                        if (!envelope.build(columns, y)) continue;
                        double* out = result.data() + static_cast<size_t>(y) * width;
                        for (int x = 0; x < width; ++x)
                          out[x] = static_cast<double>(envelope.squaredDistanceAt(x));
                      }
                    });
  return result;
}

}  // namespace limn::render::metrics
