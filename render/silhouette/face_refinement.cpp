#include "render/silhouette/face_refinement.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <utility>

namespace limn::render::silhouette {

namespace {

using Edge = std::pair<int, int>;
Edge key(int a, int b) { return {std::min(a, b), std::max(a, b)}; }

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

  // How far the chord a-b lies outside the surface at its middle, in pixels (0 if inside).
  auto sag = [&](int a, int b, FacePoint* middle) {
    const FacePoint& pa = points[a];
    const FacePoint& pb = points[b];
    Vec2 uv{0.5 * (pa.uv.x + pb.uv.x), 0.5 * (pa.uv.y + pb.uv.y)};
    subdiv::LimitSample s = domains.evaluate(face, uv);
    *middle = {uv, s.position, s.normal};
    Vec3 chord = 0.5 * (pa.position + pb.position);
    if (dot(chord - s.position, s.normal) <= 0) return 0.0;
    Vec3 c = camera.project(chord), m = camera.project(s.position);
    return std::hypot(c.x - m.x, c.y - m.y);
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
    // half would have no area in (u, v) (slivers next to a sharp corner, split many times).
    const int m = static_cast<int>(points.size());
    points.push_back(targetMiddle);
    std::vector<std::pair<size_t, std::array<int, 3>>> halves;  // (triangle, first half)
    std::vector<std::array<int, 3>> secondHalves;
    bool degenerate = false;
    for (size_t i = 0; i < triangles.size() && !degenerate; ++i) {
      const std::array<int, 3>& t = triangles[i];
      for (int k = 0; k < 3; ++k) {
        int a = t[k], b = t[(k + 1) % 3], c = t[(k + 2) % 3];
        if (key(a, b) != target) continue;
        halves.push_back({i, {a, m, c}});
        secondHalves.push_back({m, b, c});
        degenerate = !(uvArea({a, m, c}) > 0) || !(uvArea({m, b, c}) > 0);
        break;
      }
    }
    if (degenerate) {
      points.pop_back();
      sags[target].px = 0;
      continue;
    }
    for (const auto& [at, half] : halves) triangles[at] = half;
    triangles.insert(triangles.end(), secondHalves.begin(), secondHalves.end());
    ++splits;
  }
  // In 3D, no edge may be shared by more than two triangles (that would be a fold, which the
  // surface pinching near a crease has produced).
  auto folded = [&] {
    // Positions compared exactly: many splits next to a sharp corner put distinct points within
    // float rounding of each other, which is no fold.
    using Key = std::pair<std::array<double, 3>, std::array<double, 3>>;
    std::map<Key, int> uses;
    auto at = [&](int i) {
      const Vec3& p = points[i].position;
      return std::array<double, 3>{p.x, p.y, p.z};
    };
    for (const auto& t : triangles) {
      for (int k = 0; k < 3; ++k) {
        auto a = at(t[k]), b = at(t[(k + 1) % 3]);
        if (++uses[std::minmax(a, b)] > 2) return true;
      }
    }
    return false;
  };
  double areaAfter = 0;
  if (splits > 0 && tiledBefore &&
      (!tiling(&areaAfter) || std::fabs(areaAfter - areaBefore) > 1e-9 * areaBefore || folded())) {
    triangles = original;
    points.resize(originalPoints);
    return 0;
  }
  return splits;
}

}  // namespace limn::render::silhouette
