#include "render/tessellate/contour_proximity.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace limn::render::tessellate {

namespace {

double distanceToSegment(Vec2 p, Vec2 a, Vec2 b) {
  const double dx = b.x - a.x, dy = b.y - a.y;
  const double length2 = dx * dx + dy * dy;
  const double t =
      length2 > 0 ? std::clamp(((p.x - a.x) * dx + (p.y - a.y) * dy) / length2, 0.0, 1.0) : 0.0;
  return std::hypot(a.x + t * dx - p.x, a.y + t * dy - p.y);
}

double cross(Vec2 o, Vec2 a, Vec2 b) { return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x); }

double distanceBetween(const ContourPiece& p, const ContourPiece& q) {
  const double c1 = cross(p.a, p.b, q.a), c2 = cross(p.a, p.b, q.b);
  const double c3 = cross(q.a, q.b, p.a), c4 = cross(q.a, q.b, p.b);
  if (((c1 < 0) != (c2 < 0)) && ((c3 < 0) != (c4 < 0))) return 0;  // they cross
  return std::min({distanceToSegment(p.a, q.a, q.b), distanceToSegment(p.b, q.a, q.b),
                   distanceToSegment(q.a, p.a, p.b), distanceToSegment(q.b, p.a, p.b)});
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

}  // namespace

std::vector<char> ownersNearAnotherContour(const std::vector<ContourPiece>& pieces,
                                           int ownerCount, double distancePx, int width,
                                           int height,
                                           const std::function<bool(int, int)>& adjacent) {
  std::vector<char> near(ownerCount, 0);
  // A grid of cells at least twice the distance, each listing the pieces whose box (grown by
  // the distance) reaches it; a pair that is close shares a cell.
  const double cell = std::max(4.0, 2 * distancePx);
  const double margin = distancePx + cell;
  const int columns = static_cast<int>(std::ceil((width + 2 * margin) / cell));
  const int rows = static_cast<int>(std::ceil((height + 2 * margin) / cell));
  std::vector<std::vector<int>> cells(static_cast<size_t>(columns) * rows);
  auto cellRange = [&](double lo, double hi, int count) {
    const int first = static_cast<int>(std::floor((lo - distancePx + margin) / cell));
    const int last = static_cast<int>(std::floor((hi + distancePx + margin) / cell));
    return std::pair{std::max(first, 0), std::min(last, count - 1)};
  };
  for (size_t i = 0; i < pieces.size(); ++i) {
    const ContourPiece& p = pieces[i];
    const auto [x0, x1] = cellRange(std::min(p.a.x, p.b.x), std::max(p.a.x, p.b.x), columns);
    const auto [y0, y1] = cellRange(std::min(p.a.y, p.b.y), std::max(p.a.y, p.b.y), rows);
    for (int y = y0; y <= y1; ++y) {
      for (int x = x0; x <= x1; ++x) cells[static_cast<size_t>(y) * columns + x].push_back(i);
    }
  }
  for (const std::vector<int>& list : cells) {
    for (size_t i = 0; i < list.size(); ++i) {
      const ContourPiece& p = pieces[list[i]];
      for (size_t j = i + 1; j < list.size(); ++j) {
        const ContourPiece& q = pieces[list[j]];
        if (p.owner == q.owner || (near[p.owner] && near[q.owner])) continue;
        if (!nearlyParallel(p, q) || distanceBetween(p, q) > distancePx ||
            adjacent(p.owner, q.owner)) {
          continue;
        }
        near[p.owner] = near[q.owner] = 1;
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
