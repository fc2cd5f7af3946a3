#include "render/silhouette/face_refinement.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <set>
#include <utility>

#include "render/silhouette/chord_refinement.h"

namespace limn::render::silhouette {

namespace {

using Edge = std::pair<int, int>;
Edge key(int a, int b) { return {std::min(a, b), std::max(a, b)}; }

// How many triangles use each edge, the edge named by its two end positions (so that distinct
// points at one position count as one), kept as triangles come and go; folded() when an edge
// has more than two.
class EdgeUses {
 public:
  explicit EdgeUses(const std::vector<FacePoint>& points) : points_(points) {}
  void addTriangle(const std::array<int, 3>& t) { change(t, +1); }
  void removeTriangle(const std::array<int, 3>& t) { change(t, -1); }
  bool folded() const { return overused_ > 0; }

 private:
  using Position = std::array<double, 3>;
  Position at(int i) const {
    const Vec3& p = points_[i].position;
    return {p.x, p.y, p.z};
  }
  void change(const std::array<int, 3>& t, int delta) {
    for (int k = 0; k < 3; ++k) {
      const Position a = at(t[k]), b = at(t[(k + 1) % 3]);
      int& count = uses_[a < b ? std::make_pair(a, b) : std::make_pair(b, a)];
      overused_ -= count > 2;
      count += delta;
      overused_ += count > 2;
    }
  }
  const std::vector<FacePoint>& points_;
  std::map<std::pair<Position, Position>, int> uses_;
  int overused_ = 0;  // edges used more than twice
};

}  // namespace

int refineFaceTriangles(const FaceDomains& domains, const Camera& camera, int face,
                        int boundaryCount, const std::vector<std::vector<int>>& lockedChains,
                        double tolerancePx, int maxSplits, std::vector<FacePoint>& points,
                        std::vector<std::array<int, 3>>& triangles) {
  std::set<Edge> locked;
  for (int i = 0; i < boundaryCount; ++i) locked.insert(key(i, (i + 1) % boundaryCount));
  for (const std::vector<int>& chain : lockedChains) {
    for (size_t i = 0; i + 1 < chain.size(); ++i) locked.insert(key(chain[i], chain[i + 1]));
  }

  // How far the chord a-b lies outside the surface at its middle, in pixels (0 if inside;
  // outsideSide).
  const int side = outsideSide(domains.surface(), face);
  auto sag = [&](int a, int b, FacePoint* middle) {
    const FacePoint& pa = points[a];
    const FacePoint& pb = points[b];
    Vec2 uv{0.5 * (pa.uv.x + pb.uv.x), 0.5 * (pa.uv.y + pb.uv.y)};
    subdiv::LimitSample s = domains.evaluate(face, uv);
    *middle = {uv, s.position, s.normal};
    return outsidePixels(camera, 0.5 * (pa.position + pb.position), s, side);
  };

  // A split must leave the triangulation a tiling of the same domain; if numerical trouble
  // (points almost on top of each other near a crease) ever breaks that, the face keeps the
  // triangles it came with.
  auto uvArea = [&](const std::array<int, 3>& t) {
    const Vec2 &a = points[t[0]].uv, &b = points[t[1]].uv, &c = points[t[2]].uv;
    return 0.5 * ((b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x));
  };
  auto tiling = [&](double* total) {
    *total = 0;
    for (const auto& t : triangles) {
      double area = uvArea(t);
      if (!(area > 0)) return false;
      *total += area;
    }
    return true;
  };
  double areaBefore = 0;
  const bool tiledBefore = tiling(&areaBefore);
  const std::vector<std::array<int, 3>> original = triangles;
  const size_t originalPoints = points.size();

  // In 3D, no edge may be shared by more than two triangles: that would be a fold, which the
  // surface pinching next to a sharp corner produces when a midpoint lands on an existing edge.
  // Each split is checked as it is made and undone if it folds, so one bad split near a spike
  // costs only itself (checking once at the end and undoing every split of the face left whole
  // fans of chords pixels outside the outline, depending on the camera to the last bit).
  // Positions are compared exactly: many splits next to a sharp corner put distinct points
  // within float rounding of each other, which is no fold.
  EdgeUses uses(points);
  for (const auto& t : triangles) uses.addTriangle(t);
  if (uses.folded()) return 0;  // splits cannot undo a fold the face came with

  int splits = 0;
  // Each edge's sag is evaluated once: a split only adds edges.
  struct Sag {
    double px = 0;  // how far outside, 0 when within tolerance or not to be split
    FacePoint middle;
  };
  std::map<Edge, Sag> sags;
  auto sagOf = [&](const Edge& e) -> const Sag& {
    auto found = sags.find(e);
    if (found != sags.end()) return found->second;
    Sag out;
    const Vec2 &ua = points[e.first].uv, &ub = points[e.second].uv;
    const bool splittable = !locked.count(e) &&
                            std::hypot(ua.x - ub.x, ua.y - ub.y) >= 1e-6 &&  // not too short
                            length(points[e.first].position - points[e.second].position) >= 1e-9 &&
                            // along the domain's boundary a split would put a point on the face's
                            // boundary that the neighbour does not have
                            !domains.onOneSide(face, ua, ub);
    if (splittable) {
      out.px = sag(e.first, e.second, &out.middle);
      if (out.px <= tolerancePx) out.px = 0;
    }
    return sags.emplace(e, out).first->second;
  };
  while (splits < maxSplits) {
    // Find the worst interior edge still over tolerance.
    double worst = tolerancePx;
    Edge target{-1, -1};
    FacePoint targetMiddle;
    for (const auto& t : triangles) {
      for (int k = 0; k < 3; ++k) {
        const Edge e = key(t[k], t[(k + 1) % 3]);
        const Sag& s = sagOf(e);
        if (s.px > worst) {
          worst = s.px;
          target = e;
          targetMiddle = s.middle;
        }
      }
    }
    if (target.first < 0) break;

    // Split it: each triangle (a, b, c) on the edge becomes (a, m, c) and (m, b, c), unless a
    // half would have no area in (u, v) (slivers next to a sharp corner, split many times) or
    // the split folds.
    const int m = static_cast<int>(points.size());
    points.push_back(targetMiddle);
    std::vector<std::pair<size_t, std::array<int, 3>>> halves;  // (triangle, first half)
    std::vector<std::array<int, 3>> secondHalves;
    bool rejected = false;
    for (size_t i = 0; i < triangles.size() && !rejected; ++i) {
      const std::array<int, 3>& t = triangles[i];
      for (int k = 0; k < 3; ++k) {
        int a = t[k], b = t[(k + 1) % 3], c = t[(k + 2) % 3];
        if (key(a, b) != target) continue;
        halves.push_back({i, {a, m, c}});
        secondHalves.push_back({m, b, c});
        rejected = !(uvArea({a, m, c}) > 0) || !(uvArea({m, b, c}) > 0);
        break;
      }
    }
    if (!rejected) {
      for (const auto& [at, half] : halves) uses.removeTriangle(triangles[at]);
      for (const auto& [at, half] : halves) uses.addTriangle(half);
      for (const auto& half : secondHalves) uses.addTriangle(half);
      if (uses.folded()) {
        for (const auto& half : secondHalves) uses.removeTriangle(half);
        for (const auto& [at, half] : halves) uses.removeTriangle(half);
        for (const auto& [at, half] : halves) uses.addTriangle(triangles[at]);
        rejected = true;
      }
    }
    if (rejected) {
      points.pop_back();
      sags[target].px = 0;
      continue;
    }
    for (const auto& [at, half] : halves) triangles[at] = half;
    triangles.insert(triangles.end(), secondHalves.begin(), secondHalves.end());
    ++splits;
  }
  double areaAfter = 0;
  if (splits > 0 && tiledBefore &&
      (!tiling(&areaAfter) || std::fabs(areaAfter - areaBefore) > 1e-9 * areaBefore)) {
    triangles = original;
    points.resize(originalPoints);
    return 0;
  }
  return splits;
}

}  // namespace limn::render::silhouette
