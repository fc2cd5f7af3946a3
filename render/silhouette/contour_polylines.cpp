#include "render/silhouette/contour_polylines.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>

namespace limn::render::silhouette {

namespace {

// An edge point's identity: (base edge, index into that edge's points).
uint64_t key(int edge, int point) {
  return (static_cast<uint64_t>(static_cast<uint32_t>(edge)) << 32) | static_cast<uint32_t>(point);
}
uint64_t fromKey(const ContourCurve& c) { return key(c.fromEdge, c.fromPoint); }
uint64_t toKey(const ContourCurve& c) { return key(c.toEdge, c.toPoint); }

// Which curves end at each edge point, as (curve, end) with end 0 = from, 1 = to.
using Incidence = std::unordered_map<uint64_t, std::vector<std::pair<int, int>>>;

PolylinePoint polylinePoint(const FacePoint& p, int face, bool edgePoint, const Camera& camera) {
  return {p.position, p.normal, camera.project(p.position), face, p.uv, edgePoint};
}

class Chainer {
 public:
  Chainer(const std::vector<ContourCurve>& curves, const Camera& camera)
      : curves_(curves), camera_(camera), used_(curves.size(), false) {
    for (int i = 0; i < static_cast<int>(curves.size()); ++i) {
      incidence_[fromKey(curves[i])].push_back({i, 0});
      incidence_[toKey(curves[i])].push_back({i, 1});
    }
  }

  // Open chains first start at edge points only one curve uses, then whatever is left is
  // made of loops; the closed ones are listed first in the result.
  std::vector<ContourPolyline> chainAll() {
    std::vector<ContourPolyline> open, closed;
    for (int i = 0; i < static_cast<int>(curves_.size()); ++i) {
      for (int end = 0; end < 2 && !used_[i]; ++end) {
        uint64_t k = end == 0 ? fromKey(curves_[i]) : toKey(curves_[i]);
        if (incidence_[k].size() == 1) open.push_back(walk(i, end));
      }
    }
    for (int i = 0; i < static_cast<int>(curves_.size()); ++i) {
      if (used_[i]) continue;
      ContourPolyline line = walk(i, 0);
      (line.closed ? closed : open).push_back(std::move(line));
    }
    std::stable_sort(open.begin(), open.end(), [](const auto& a, const auto& b) {
      return a.curves.front() < b.curves.front();
    });
    closed.insert(closed.end(), std::make_move_iterator(open.begin()),
                  std::make_move_iterator(open.end()));
    return closed;
  }

 private:
  // Appends curve `i` entered at its end `end` (0: from, 1: to) and returns the key of the
  // edge point it leaves by.
  uint64_t append(ContourPolyline& line, int i, int end) {
    const ContourCurve& c = curves_[i];
    used_[i] = true;
    line.curves.push_back(i);
    const int n = static_cast<int>(c.points.size());
    const bool first = line.points.empty();
    for (int k = first ? 0 : 1; k < n; ++k) {  // a continuation shares its first point
      int index = end == 0 ? k : n - 1 - k;
      line.points.push_back(polylinePoint(c.points[index], c.face, k == 0 || k == n - 1, camera_));
    }
    return end == 0 ? toKey(c) : fromKey(c);
  }

  ContourPolyline walk(int start, int end) {
    ContourPolyline line;
    const uint64_t origin = end == 0 ? fromKey(curves_[start]) : toKey(curves_[start]);
    uint64_t at = append(line, start, end);
    while (true) {
      if (at == origin) {
        line.closed = true;
        break;
      }
      int next = -1, nextEnd = 0;
      for (const auto& [curve, e] : incidence_[at]) {
        if (!used_[curve]) {
          next = curve;
          nextEnd = e;
          break;
        }
      }
      if (next < 0) break;
      at = append(line, next, nextEnd);
    }
    // The last point of a closed chain is its first: keep it once.
    if (line.closed && line.points.size() > 1) line.points.pop_back();
    return line;
  }

  const std::vector<ContourCurve>& curves_;
  const Camera& camera_;
  std::vector<bool> used_;
  Incidence incidence_;
};

}  // namespace

std::vector<ContourPolyline> chainContourCurves(const std::vector<ContourCurve>& curves,
                                                const Camera& camera) {
  return Chainer(curves, camera).chainAll();
}

double distanceFromSurface(const subdiv::LimitSurface& surface, const PolylinePoint& point) {
  if (point.face < 0 || !surface.hasLimit(point.face)) return 0.0;
  subdiv::LimitSample s = surface.evaluate(point.face, point.uv.x, point.uv.y);
  return std::fabs(dot(point.position - s.position, s.normal));
}

std::vector<PolylinePiece> splitPieces(ContourPolyline& polyline, std::vector<bool>& visible) {
  const int n = static_cast<int>(polyline.points.size());
  std::vector<PolylinePiece> pieces;
  if (n == 0) return pieces;
  if (polyline.closed) {
    // Start at a change of visibility, so that no piece wraps around the end.
    int first = 0;
    while (first < n && visible[first] == visible[(first + n - 1) % n]) ++first;
    if (first < n && first > 0) {
      std::rotate(polyline.points.begin(), polyline.points.begin() + first, polyline.points.end());
      std::rotate(visible.begin(), visible.begin() + first, visible.end());
    }
  }
  int start = 0;
  for (int i = 1; i <= n; ++i) {
    if (i == n || visible[i] != visible[start]) {
      pieces.push_back({start, i - 1, static_cast<bool>(visible[start])});
      start = i;
    }
  }
  return pieces;
}

}  // namespace limn::render::silhouette
