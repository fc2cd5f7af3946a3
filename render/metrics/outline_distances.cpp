// compareOutlines: see outline.h. Every located point of one outline, except those of closed
// loops thinner than the caller can resolve, is measured to the nearest segment of the other
// through a bucket grid of segments, and where it is more than kRemeasurePx away, to the other's
// geometry when the caller has it.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include "render/metrics/coverage_distance.h"
#include "render/metrics/outline.h"

namespace limn::render::metrics {

namespace {
// The segments of an outline (lone points as zero-length ones) bucketed in a uniform grid, for
// nearest-segment queries that look at a few cells around the query point.
class SegmentIndex {
 public:
  SegmentIndex(const Outline& outline, double x0, double y0, double x1, double y1)
      : outline_(outline) {
    std::vector<char> joined(outline.points.size(), 0);
    for (auto [a, b] : outline.segments) {
      items_.push_back({a, b});
      joined[a] = joined[b] = 1;
    }
    for (size_t k = 0; k < joined.size(); ++k) {
      if (!joined[k]) items_.push_back({static_cast<int>(k), static_cast<int>(k)});
    }
    // About four cells per item, at least half a pixel each.
    double area = std::max(1.0, (x1 - x0) * (y1 - y0));
    cell_ = std::max(0.5, std::sqrt(area / (4.0 * std::max<size_t>(1, items_.size()))));
    x0_ = x0;
    y0_ = y0;
    nx_ = std::max(1, static_cast<int>(std::ceil((x1 - x0) / cell_)));
    ny_ = std::max(1, static_cast<int>(std::ceil((y1 - y0) / cell_)));
    std::vector<int> counts(static_cast<size_t>(nx_) * ny_ + 1, 0);
    forEachCell([&](size_t cell, int) { ++counts[cell + 1]; });
    for (size_t c = 1; c < counts.size(); ++c) counts[c] += counts[c - 1];
    start_ = counts;
    entries_.resize(counts.back());
    forEachCell([&](size_t cell, int item) { entries_[counts[cell]++] = item; });
  }

  // Distance from p (inside the index's bounds) to the nearest item.
  double nearest(Vec2 p) const {
    constexpr int kMaxRing = 16;  // beyond it, every item is looked at
    int cx = cellX(p.x), cy = cellY(p.y);
    double best = std::numeric_limits<double>::infinity();
    for (int ring = 0; ring <= kMaxRing; ++ring) {
      for (int y = cy - ring; y <= cy + ring; ++y) {
        if (y < 0 || y >= ny_) continue;
        bool edgeRow = y == cy - ring || y == cy + ring;
        for (int x = cx - ring; x <= cx + ring; x += edgeRow ? 1 : 2 * std::max(ring, 1)) {
          if (x < 0 || x >= nx_) continue;
          size_t cell = static_cast<size_t>(y) * nx_ + x;
          for (int k = start_[cell]; k < start_[cell + 1]; ++k)
            best = std::min(best, distance(p, entries_[k]));
        }
      }
      // Items in rings further out are at least `ring` cells away.
      if (best <= ring * cell_) return best;
    }
    for (size_t k = 0; k < items_.size(); ++k)
      best = std::min(best, distance(p, static_cast<int>(k)));
    return best;
  }

 private:
  int cellX(double x) const { return std::clamp(static_cast<int>((x - x0_) / cell_), 0, nx_ - 1); }
  int cellY(double y) const { return std::clamp(static_cast<int>((y - y0_) / cell_), 0, ny_ - 1); }
  double distance(Vec2 p, int item) const {
    return pointSegmentDistance(p, outline_.points[items_[item].first],
                                outline_.points[items_[item].second]);
  }
  template <typename Fn>
  void forEachCell(Fn fn) const {
    for (size_t k = 0; k < items_.size(); ++k) {
      Vec2 a = outline_.points[items_[k].first], b = outline_.points[items_[k].second];
      for (int y = cellY(std::min(a.y, b.y)); y <= cellY(std::max(a.y, b.y)); ++y) {
        for (int x = cellX(std::min(a.x, b.x)); x <= cellX(std::max(a.x, b.x)); ++x) {
          fn(static_cast<size_t>(y) * nx_ + x, static_cast<int>(k));
        }
      }
    }
  }

  const Outline& outline_;
  std::vector<std::pair<int, int>> items_;
  double cell_ = 1, x0_ = 0, y0_ = 0;
  int nx_ = 1, ny_ = 1;
  std::vector<int> start_, entries_;
};

double cross(Vec2 o, Vec2 a, Vec2 b) {
  return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
}

// The least width of the convex hull of `points`: over the hull's edges, the farthest hull
// point from the edge's line, and the least of those. 0 for fewer than three points or points
// on one line.
double hullWidth(std::vector<Vec2> points) {
  std::sort(points.begin(), points.end(),
            [](Vec2 a, Vec2 b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
  std::vector<Vec2> hull(2 * points.size());
  size_t k = 0;
  for (size_t i = 0; i < points.size(); ++i) {  // Andrew's monotone chain, lower then upper
    while (k >= 2 && cross(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
    hull[k++] = points[i];
  }
  for (size_t i = points.size() - 1, lower = k + 1; i-- > 0;) {
    while (k >= lower && cross(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
    hull[k++] = points[i];
  }
  hull.resize(k > 0 ? k - 1 : 0);
  if (hull.size() < 3) return 0;
  double width = std::numeric_limits<double>::infinity();
  for (size_t e = 0; e < hull.size(); ++e) {
    const Vec2 a = hull[e], b = hull[(e + 1) % hull.size()];
    const double length = std::hypot(b.x - a.x, b.y - a.y);
    if (length == 0) continue;
    double farthest = 0;
    for (Vec2 p : hull) farthest = std::max(farthest, std::abs(cross(a, b, p)) / length);
    width = std::min(width, farthest);
  }
  return width;
}

// The closed loops of `outline` (components whose every point joins exactly two segments) of at
// most kMaxThinLoopPoints points whose convex hull is thinner than `resolvablePx`, as a mark per
// point. The bound keeps the hull's quadratic width off the long outlines (a loop a few samples
// long has a dozen points; one thinner than a sample follows a sample row or column, as a
// slanted one breaks into single-sample loops).
constexpr size_t kMaxThinLoopPoints = 64;

std::vector<char> thinLoops(const Outline& outline, double resolvablePx, size_t& loops) {
  const size_t n = outline.points.size();
  std::vector<char> thin(n, 0);
  if (resolvablePx <= 0) return thin;
  std::vector<int> parent(n), degree(n, 0);
  for (size_t k = 0; k < n; ++k) parent[k] = static_cast<int>(k);
  auto root = [&](int k) {
    while (parent[k] != k) k = parent[k] = parent[parent[k]];
    return k;
  };
  for (auto [a, b] : outline.segments) {
    ++degree[a];
    ++degree[b];
    parent[root(a)] = root(b);
  }
  // Per component: its size, and whether every point joins two segments.
  std::vector<size_t> size(n, 0);
  std::vector<char> closed(n, 1);
  for (size_t k = 0; k < n; ++k) {
    const int r = root(static_cast<int>(k));
    ++size[r];
    if (degree[k] != 2) closed[r] = 0;
  }
  auto candidate = [&](int r) {
    return closed[r] && size[r] >= 3 && size[r] <= kMaxThinLoopPoints;
  };
  // The points of the small closed loops only (the long outlines are not copied).
  std::vector<std::vector<Vec2>> members(n);
  for (size_t k = 0; k < n; ++k) {
    const int r = root(static_cast<int>(k));
    if (candidate(r)) members[r].push_back(outline.points[k]);
  }
  std::vector<char> dropRoot(n, 0);
  for (size_t r = 0; r < n; ++r) {
    if (members[r].empty() || hullWidth(members[r]) >= resolvablePx) continue;
    dropRoot[r] = 1;
    ++loops;
  }
  for (size_t k = 0; k < n; ++k) thin[k] = dropRoot[root(static_cast<int>(k))];
  return thin;
}

bool insideFrame(const Outline& o, Vec2 p) {
  return p.x >= 0.5 && p.y >= 0.5 && p.x <= o.frameWidth - 0.5 && p.y <= o.frameHeight - 0.5;
}

// Points further than this from the other outline are measured again on the other's geometry
// when it can be (coverage_distance.h).
constexpr double kRemeasurePx = 0.1;

// Distances from every point of `from` inside its frame and not marked in `unresolved` to the
// nearest item of `index`, lowered to the distance to `toGeometry` (when given) where that is
// nearer.
std::vector<double> directedDistances(const Outline& from, const std::vector<char>& unresolved,
                                      const SegmentIndex& index,
                                      const CoverageDistanceQuery* toGeometry) {
  std::vector<Vec2> measured;
  for (size_t k = 0; k < from.points.size(); ++k) {
    if (!unresolved[k] && insideFrame(from, from.points[k])) measured.push_back(from.points[k]);
  }
  std::vector<double> d(measured.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, d.size(), 256),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t k = r.begin(); k < r.end(); ++k)
                        d[k] = index.nearest(measured[k]);
                    });
  if (!toGeometry) return d;
  std::vector<size_t> far;
  std::vector<Vec2> points;
  std::vector<double> bounds;
  for (size_t k = 0; k < d.size(); ++k) {
    if (d[k] <= kRemeasurePx) continue;
    far.push_back(k);
    points.push_back(measured[k]);
    bounds.push_back(d[k]);
  }
  if (far.empty()) return d;
  lowerLargestFirst(*toGeometry, points, bounds);
  for (size_t i = 0; i < far.size(); ++i) d[far[i]] = std::min(d[far[i]], bounds[i]);
  return d;
}

}  // namespace

OutlineDistances compareOutlines(const Outline& a, const Outline& b, double farPx,
                                 const CoverageDistanceQuery* geometryA,
                                 const CoverageDistanceQuery* geometryB, double resolvablePx) {
  OutlineDistances result;
  // Loops too thin to resolve are not measured, but stay targets: the other picture's feature
  // next to one is not missing.
  const std::vector<char> thinA = thinLoops(a, resolvablePx, result.unresolvedLoops);
  const std::vector<char> thinB = thinLoops(b, resolvablePx, result.unresolvedLoops);
  const auto resolved = [](const std::vector<char>& thin) {
    return std::find(thin.begin(), thin.end(), 0) != thin.end();
  };
  if (!resolved(thinA) && !resolved(thinB)) return result;
  if (a.empty() || b.empty()) return {farPx, farPx, result.unresolvedLoops};
  double x0 = std::numeric_limits<double>::infinity(), y0 = x0, x1 = -x0, y1 = -x0;
  for (const Outline* o : {&a, &b}) {
    for (Vec2 p : o->points) {
      x0 = std::min(x0, p.x);
      y0 = std::min(y0, p.y);
      x1 = std::max(x1, p.x);
      y1 = std::max(y1, p.y);
    }
  }
  SegmentIndex indexA(a, x0, y0, x1, y1), indexB(b, x0, y0, x1, y1);
  std::vector<double> ab = directedDistances(a, thinA, indexB, geometryB);
  std::vector<double> ba = directedDistances(b, thinB, indexA, geometryA);
  double sum = 0;
  for (const std::vector<double>* d : {&ab, &ba}) {
    for (double v : *d) {
      result.hausdorffPx = std::max(result.hausdorffPx, v);
      sum += v;
    }
  }
  if (!ab.empty() || !ba.empty()) result.meanPx = sum / static_cast<double>(ab.size() + ba.size());
  return result;
}

}  // namespace limn::render::metrics
