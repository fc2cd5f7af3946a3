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
  std::set<Edge> checked;  // interior edges found fine (their chord is within tolerance)
  while (splits < maxSplits) {
    // Find the worst interior edge still over tolerance.
    double worst = tolerancePx;
    Edge target{-1, -1};
    FacePoint targetMiddle;
    for (const auto& t : triangles) {
      for (int k = 0; k < 3; ++k) {
        Edge e = key(t[k], t[(k + 1) % 3]);
        if (locked.count(e) || checked.count(e)) continue;
        const Vec2 &ua = points[e.first].uv, &ub = points[e.second].uv;
        if (std::hypot(ua.x - ub.x, ua.y - ub.y) < 1e-6 ||  // too short to split further
            length(points[e.first].position - points[e.second].position) < 1e-9 ||
            // along the domain's boundary: a split there would put a point on the face's
            // boundary that the neighbour does not have
            domains.onOneSide(face, ua, ub)) {
          checked.insert(e);
          continue;
        }
        FacePoint middle;
        double s = sag(e.first, e.second, &middle);
        if (s > worst) {
          worst = s;
          target = e;
          targetMiddle = middle;
        } else if (s <= tolerancePx) {
          checked.insert(e);
        }
      }
    }
    if (target.first < 0) break;

    // Split it: each triangle (a, b, c) on the edge becomes (a, m, c) and (m, b, c).
    const int m = static_cast<int>(points.size());
    points.push_back(targetMiddle);
    const size_t count = triangles.size();
    for (size_t i = 0; i < count; ++i) {
      std::array<int, 3> t = triangles[i];
      for (int k = 0; k < 3; ++k) {
        int a = t[k], b = t[(k + 1) % 3], c = t[(k + 2) % 3];
        if (key(a, b) != target) continue;
        triangles[i] = {a, m, c};
        triangles.push_back({m, b, c});
        break;
      }
    }
    ++splits;
  }
  // In 3D, no edge may be shared by more than two triangles (that would be a fold, which the
  // surface pinching near a crease has produced).
  auto folded = [&] {
    using Key = std::pair<std::array<float, 3>, std::array<float, 3>>;
    std::map<Key, int> uses;
    auto at = [&](int i) {
      const Vec3& p = points[i].position;
      return std::array<float, 3>{static_cast<float>(p.x), static_cast<float>(p.y),
                                  static_cast<float>(p.z)};
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
