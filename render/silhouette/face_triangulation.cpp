#include "render/silhouette/face_triangulation.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

namespace limn::render::silhouette {

namespace {

// True when p lies inside or on triangle abc (counter-clockwise), with tolerance `eps`.
bool inTriangle(const Vec2& p, const Vec2& a, const Vec2& b, const Vec2& c, double eps) {
  return cross2(a, b, p) >= -eps && cross2(b, c, p) >= -eps && cross2(c, a, p) >= -eps;
}

bool samePoint(const Vec2& a, const Vec2& b) { return a.x == b.x && a.y == b.y; }

// Positive when d lies inside the circle through a, b, c (counter-clockwise).
double inCircle(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d) {
  const double ax = a.x - d.x, ay = a.y - d.y, bx = b.x - d.x, by = b.y - d.y;
  const double cx = c.x - d.x, cy = c.y - d.y;
  return (ax * ax + ay * ay) * (bx * cy - cx * by) - (bx * bx + by * by) * (ax * cy - cx * ay) +
         (cx * cx + cy * cy) * (ax * by - bx * ay);
}

// Lawson's flips over triangles[first..]: a diagonal shared by two of them is swapped while the
// fourth corner of their quad lies inside the circle of the other three, which ends in the
// polygon's constrained Delaunay triangulation. Ear clipping alone leaves fans of long, thin
// triangles from one corner to the far side (a contour curve's samples, an n-gon's rim): their
// chords cross the face and sag far off the surface, each costing the chord refinement splits.
void flipToDelaunay(const std::vector<Vec2>& uv, double scale, size_t first,
                    std::vector<std::array<int, 3>>& triangles) {
  const double areaEps = 1e-14 * std::max(scale * scale, 1e-30);
  const double circleEps = 1e-12 * std::max(scale * scale * scale * scale, 1e-30);
  std::map<std::pair<int, int>, size_t> directed;  // edge a->b: the triangle that has it
  for (size_t t = first; t < triangles.size(); ++t) {
    for (int k = 0; k < 3; ++k) directed[{triangles[t][k], triangles[t][(k + 1) % 3]}] = t;
  }
  // Each flip makes the triangulation strictly more Delaunay, so the passes end; the cap only
  // guards against rounding at ties.
  const size_t maxPasses = 4 * (triangles.size() - first) + 4;
  bool flipped = true;
  for (size_t pass = 0; flipped && pass < maxPasses; ++pass) {
    flipped = false;
    for (size_t t = first; t < triangles.size(); ++t) {
      for (int k = 0; k < 3; ++k) {
        const int p = triangles[t][k], q = triangles[t][(k + 1) % 3], r = triangles[t][(k + 2) % 3];
        auto across = directed.find({q, p});
        if (across == directed.end()) continue;
        const size_t u = across->second;
        const std::array<int, 3>& other = triangles[u];
        const int s = other[0] != p && other[0] != q   ? other[0]
                      : other[1] != p && other[1] != q ? other[1]
                                                       : other[2];
        // The quad p, s, q, r must be strictly convex for the diagonal r-s to replace p-q.
        if (cross2(uv[p], uv[s], uv[r]) <= areaEps || cross2(uv[s], uv[q], uv[r]) <= areaEps) {
          continue;
        }
        if (inCircle(uv[p], uv[q], uv[r], uv[s]) <= circleEps) continue;
        triangles[t] = {p, s, r};
        triangles[u] = {s, q, r};
        directed.erase({p, q});
        directed.erase({q, p});
        directed[{p, s}] = t;
        directed[{s, r}] = t;
        directed[{r, s}] = u;
        directed[{q, r}] = u;
        flipped = true;
        break;  // triangle t changed: its edges are read again on the next pass
      }
    }
  }
}

}  // namespace

void earClip(const std::vector<Vec2>& uv, std::vector<int> polygon,
             std::vector<std::array<int, 3>>& triangles) {
  const size_t first = triangles.size();
  double scale = 0;
  for (int i : polygon) scale = std::max({scale, std::fabs(uv[i].x), std::fabs(uv[i].y)});
  const double areaEps = 1e-14 * std::max(scale * scale, 1e-30);

  size_t cursor = 0;
  while (polygon.size() > 3) {
    const size_t n = polygon.size();
    bool clipped = false;
    for (size_t step = 0; step < n && !clipped; ++step) {
      size_t i = (cursor + step) % n;
      int a = polygon[(i + n - 1) % n], b = polygon[i], c = polygon[(i + 1) % n];
      if (cross2(uv[a], uv[b], uv[c]) <= areaEps) continue;  // reflex or straight
      bool empty = true;
      for (size_t j = 0; j < n && empty; ++j) {
        int q = polygon[j];
        if (q == a || q == b || q == c) continue;
        if (samePoint(uv[q], uv[a]) || samePoint(uv[q], uv[b]) || samePoint(uv[q], uv[c])) continue;
        if (inTriangle(uv[q], uv[a], uv[b], uv[c], areaEps)) empty = false;
      }
      if (!empty) continue;
      triangles.push_back({a, b, c});
      polygon.erase(polygon.begin() + static_cast<long>(i));
      cursor = i == 0 ? 0 : i - 1;
      clipped = true;
    }
    if (!clipped) {
      // No clean ear (a numerically degenerate polygon): cut the convex corner with the
      // largest area regardless, so the face is still covered.
      size_t best = 0;
      double bestArea = -1e300;
      for (size_t i = 0; i < n; ++i) {
        double area =
            cross2(uv[polygon[(i + n - 1) % n]], uv[polygon[i]], uv[polygon[(i + 1) % n]]);
        if (area > bestArea) {
          bestArea = area;
          best = i;
        }
      }
      if (bestArea > areaEps) {
        triangles.push_back({polygon[(best + n - 1) % n], polygon[best], polygon[(best + 1) % n]});
      }
      polygon.erase(polygon.begin() + static_cast<long>(best));
      cursor = 0;
    }
  }
  if (polygon.size() == 3 && cross2(uv[polygon[0]], uv[polygon[1]], uv[polygon[2]]) > areaEps) {
    triangles.push_back({polygon[0], polygon[1], polygon[2]});
  }
  flipToDelaunay(uv, scale, first, triangles);
}

std::vector<std::array<int, 3>> triangulateFace(const std::vector<Vec2>& uv, int boundaryCount,
                                                const std::vector<CurvePath>& curves) {
  std::vector<std::vector<int>> regions(1);
  for (int i = 0; i < boundaryCount; ++i) regions[0].push_back(i);

  for (const CurvePath& curve : curves) {
    for (size_t r = 0; r < regions.size(); ++r) {
      std::vector<int>& region = regions[r];
      auto ia = std::find(region.begin(), region.end(), curve.from);
      auto ib = std::find(region.begin(), region.end(), curve.to);
      if (ia == region.end() || ib == region.end()) continue;
      // Rotate so the region starts at `from`: [from, ..., to, ...].
      std::rotate(region.begin(), ia, region.end());
      size_t toAt =
          static_cast<size_t>(std::find(region.begin(), region.end(), curve.to) - region.begin());
      // First part: from -> (boundary) -> to -> (curve backwards) -> from.
      std::vector<int> first(region.begin(), region.begin() + static_cast<long>(toAt) + 1);
      first.insert(first.end(), curve.interior.rbegin(), curve.interior.rend());
      // Second part: to -> (boundary) -> from -> (curve forwards) -> to.
      std::vector<int> second(region.begin() + static_cast<long>(toAt), region.end());
      second.push_back(curve.from);
      second.insert(second.end(), curve.interior.begin(), curve.interior.end());
      region = std::move(first);
      regions.push_back(std::move(second));
      break;
    }
  }
  std::vector<std::array<int, 3>> triangles;
  for (const std::vector<int>& region : regions) earClip(uv, region, triangles);
  return triangles;
}

}  // namespace limn::render::silhouette
