#include "render/tessellate/contour_proximity.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <utility>

namespace limn::render::tessellate {

namespace {

// Distance between two pieces: 0 where they cross, else the nearest of their ends to the other.
double distanceBetween(const ContourPiece& p, const ContourPiece& q) {
  if (segmentsCross(p.a, p.b, q.a, q.b)) return 0;
  return std::min({distanceToSegment2D(p.a, q.a, q.b), distanceToSegment2D(p.b, q.a, q.b),
                   distanceToSegment2D(q.a, p.a, p.b), distanceToSegment2D(q.b, p.a, p.b)});
}

// Whether the pieces' lines are within kGrazingDegrees of each other (either way along them).
// Contours that cross at a wider angle meet where they cross, give or take the error itself.
bool nearlyParallel(const ContourPiece& p, const ContourPiece& q) {
  constexpr double kGrazingDegrees = 20;
  static const double kSine = std::sin(kGrazingDegrees * std::numbers::pi / 180);
  const double px = p.b.x - p.a.x, py = p.b.y - p.a.y, qx = q.b.x - q.a.x, qy = q.b.y - q.a.y;
  const double lengths = std::hypot(px, py) * std::hypot(qx, qy);
  return std::abs(px * qy - py * qx) <= kSine * lengths;
}

// The part of segment a-b inside the box [lo, hi] (Liang-Barsky), or false if none.
bool clipToBox(Vec2& a, Vec2& b, Vec2 lo, Vec2 hi) {
  if (!std::isfinite(a.x + a.y + b.x + b.y)) return false;  // a degenerate normal's NaN
  double t0 = 0, t1 = 1;
  const double d[2] = {b.x - a.x, b.y - a.y}, from[2] = {a.x, a.y};
  const double low[2] = {lo.x, lo.y}, high[2] = {hi.x, hi.y};
  for (int axis = 0; axis < 2; ++axis) {
    if (d[axis] == 0) {
      if (from[axis] < low[axis] || from[axis] > high[axis]) return false;
      continue;
    }
    double enter = (low[axis] - from[axis]) / d[axis], leave = (high[axis] - from[axis]) / d[axis];
    if (enter > leave) std::swap(enter, leave);
    t0 = std::max(t0, enter);
    t1 = std::min(t1, leave);
    if (t0 > t1) return false;
  }
  const Vec2 start = a;
  a = {start.x + t0 * d[0], start.y + t0 * d[1]};
  b = {start.x + t1 * d[0], start.y + t1 * d[1]};
  return true;
}

}  // namespace

std::vector<char> ownersNearAnotherContour(const std::vector<ContourPiece>& pieces, int ownerCount,
                                           double distancePx, int width, int height,
                                           const std::function<bool(int, int)>& adjacent) {
  std::vector<char> near(ownerCount, 0);
  // Each piece (clipped to the image and a margin) lists the grid cells of its points every
  // half cell. Two pieces within distancePx <= cell / 2 have points within a quarter cell of
  // their nearest points, so at most a cell apart: in the same or neighbouring cells. Memory
  // follows the pieces' length, not the image's area.
  const double cell = std::max(4.0, 2 * distancePx);
  const Vec2 lo{-distancePx, -distancePx}, hi{width + distancePx, height + distancePx};
  const int64_t columns = static_cast<int64_t>(std::ceil((hi.x - lo.x) / cell)) + 1;
  std::vector<std::pair<int64_t, int>> entries;  // (cell, piece), sorted by cell
  for (size_t i = 0; i < pieces.size(); ++i) {
    Vec2 a = pieces[i].a, b = pieces[i].b;
    if (!clipToBox(a, b, lo, hi)) continue;
    const int steps = 1 + static_cast<int>(std::hypot(b.x - a.x, b.y - a.y) / (cell / 2));
    int64_t last = -1;
    for (int k = 0; k <= steps; ++k) {
      const double t = static_cast<double>(k) / steps;
      const int64_t cx = static_cast<int64_t>((a.x + t * (b.x - a.x) - lo.x) / cell);
      const int64_t cy = static_cast<int64_t>((a.y + t * (b.y - a.y) - lo.y) / cell);
      const int64_t key = cy * columns + cx;
      if (key != last) entries.push_back({key, static_cast<int>(i)});
      last = key;
    }
  }
  std::sort(entries.begin(), entries.end());
  entries.erase(std::unique(entries.begin(), entries.end()), entries.end());
  auto compare = [&](int i, int j) {
    const ContourPiece& p = pieces[i];
    const ContourPiece& q = pieces[j];
    if (p.owner == q.owner || (near[p.owner] && near[q.owner])) return;
    if (!nearlyParallel(p, q) || distanceBetween(p, q) > distancePx || adjacent(p.owner, q.owner)) {
      return;
    }
    near[p.owner] = near[q.owner] = 1;
  };
  for (const auto& [key, piece] : entries) {
    // This cell and the neighbours after it in the sort (the others see this one).
    for (const int64_t other :
         {key, key + 1, key + columns - 1, key + columns, key + columns + 1}) {
      auto it = std::lower_bound(entries.begin(), entries.end(), std::pair<int64_t, int>{other, 0});
      for (; it != entries.end() && it->first == other; ++it) {
        if (other != key || it->second > piece) compare(piece, it->second);
      }
    }
  }
  return near;
}

void appendContourPieces(const std::vector<Vec2>& points, const std::vector<double>& facing,
                         int owner, std::vector<ContourPiece>& out) {
  std::vector<Vec2> changes;
  const size_t n = points.size();
  for (size_t i = 0; i < n; ++i) {
    const size_t j = (i + 1) % n;
    if ((facing[i] < 0) == (facing[j] < 0)) continue;
    const double t = facing[i] / (facing[i] - facing[j]);
    changes.push_back({points[i].x + t * (points[j].x - points[i].x),
                       points[i].y + t * (points[j].y - points[i].y)});
  }
  if (changes.size() == 2) {
    out.push_back({changes[0], changes[1], owner});
  } else if (changes.size() > 2) {
    for (size_t k = 0; k < changes.size(); ++k) {
      out.push_back({changes[k], changes[(k + 1) % changes.size()], owner});
    }
  }
}

}  // namespace limn::render::tessellate
