#include "render/normalmap/nearest_feature.h"

#include <stdexcept>

#include "render/core/parallel.h"

namespace limn::render::normalmap {

namespace {

constexpr int32_t kNone = -1;

// Pass 1: for each pixel, the row of the nearest feature in its column (kNone if the column has
// none). Two sweeps over the rows for a stripe of columns [x0, x1), row by row so memory is
// read in order.
void columnNearest(const std::vector<uint8_t>& feature, int width, int height, int x0, int x1,
                   std::vector<int32_t>& rows) {
  std::vector<int32_t> last(static_cast<size_t>(x1 - x0), kNone);
  for (int y = 0; y < height; ++y) {
    const size_t base = static_cast<size_t>(y) * width;
    for (int x = x0; x < x1; ++x) {
      if (feature[base + x]) last[x - x0] = y;
      rows[base + x] = last[x - x0];
    }
  }
  std::vector<int32_t> next(static_cast<size_t>(x1 - x0), kNone);
  for (int y = height - 1; y >= 0; --y) {
    const size_t base = static_cast<size_t>(y) * width;
    for (int x = x0; x < x1; ++x) {
      if (feature[base + x]) next[x - x0] = y;
      const int32_t below = next[x - x0], above = rows[base + x];
      if (below != kNone && (above == kNone || below - y < y - above)) rows[base + x] = below;
    }
  }
}

// Pass 2 for row y: the lower envelope of the parabolas (x - q)^2 + g_q^2 rooted at the
// columns q that have a feature, g_q = y - rows[q]. Writes the nearest feature's index.
class RowEnvelope {
 public:
  void run(const std::vector<int32_t>& rows, int width, int y, std::vector<int64_t>& out) {
    const size_t base = static_cast<size_t>(y) * width;
    roots_.clear();
    heights_.clear();
    starts_.clear();
    for (int q = 0; q < width; ++q) {
      const int32_t row = rows[base + q];
      if (row == kNone) continue;
      const int64_t g = static_cast<int64_t>(y) - row;
      const int64_t h = g * g;
      // Drop the parabolas the new one lies under from where they would start to be lowest.
      double start = -1e300;
      while (!roots_.empty()) {
        start = intersection(roots_.back(), heights_.back(), q, h);
        if (start > starts_.back()) break;
        roots_.pop_back();
        heights_.pop_back();
        starts_.pop_back();
        start = -1e300;
      }
      roots_.push_back(q);
      heights_.push_back(h);
      starts_.push_back(start);
    }
    if (roots_.empty()) return;  // only when the whole image has no feature
    size_t k = 0;
    for (int x = 0; x < width; ++x) {
      while (k + 1 < roots_.size() && starts_[k + 1] <= x) ++k;
      const int q = roots_[k];
      out[base + x] = static_cast<int64_t>(rows[base + q]) * width + q;
    }
  }

 private:
  // Where parabola (p, hp) and parabola (q, hq), p < q, are equally low.
  static double intersection(int p, int64_t hp, int q, int64_t hq) {
    const double dp = p, dq = q;
    return ((static_cast<double>(hq) + dq * dq) - (static_cast<double>(hp) + dp * dp)) /
           (2.0 * (dq - dp));
  }

  std::vector<int> roots_;
  std::vector<int64_t> heights_;
  std::vector<double> starts_;
};

}  // namespace

std::vector<int64_t> nearestFeature(const std::vector<uint8_t>& feature, int width, int height) {
  if (width < 0 || height < 0) throw std::invalid_argument("nearestFeature: negative size");
  const size_t count = static_cast<size_t>(width) * height;
  if (feature.size() != count) {
    throw std::invalid_argument("nearestFeature: the mask is not width x height");
  }
  std::vector<int64_t> out(count, -1);
  if (count == 0) return out;
  std::vector<int32_t> rows(count);
  constexpr int kStripe = 256;
  const size_t stripes = (static_cast<size_t>(width) + kStripe - 1) / kStripe;
  parallelFor(stripes, 1, [&](size_t begin, size_t end) {
    for (size_t s = begin; s < end; ++s) {
      const int x0 = static_cast<int>(s) * kStripe;
      columnNearest(feature, width, height, x0, std::min(width, x0 + kStripe), rows);
    }
  });
  parallelFor(static_cast<size_t>(height), 16, [&](size_t begin, size_t end) {
    RowEnvelope envelope;
    for (size_t y = begin; y < end; ++y) envelope.run(rows, width, static_cast<int>(y), out);
  });
  return out;
}

}  // namespace limn::render::normalmap
