// meshCoverageDistance: see coverage_distance.h. The points to measure are few (the outline
// samples the sampled distances put more than a sample away from the other outline), the
// triangles many (a reference has up to millions), so the points go into a grid, each in every
// cell its search disc reaches, and every triangle visits the cells under its bounding box.
// The triangles are filed by image-plane bucket once per query, so each batch of points visits
// only the triangles near its grid (a batch along an outline: a few percent of them) instead of
// passing over all of them.
#include "render/metrics/coverage_distance.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>
#include <tuple>
#include <utility>

namespace limn::render::metrics {

namespace {

constexpr double kMinCellPx = 4;
constexpr int kMaxCellsPerSide = 512;
constexpr size_t kTriangleGrain = 8192;
constexpr size_t kFirstBatch = 256;

double cross(const Vec2& a, const Vec2& b, const Vec2& p) {
  return (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x);
}

// The points, each listed in every cell its disc (radius: its current bound) overlaps.
class PointGrid {
 public:
  PointGrid(const std::vector<Vec2>& points, const std::vector<double>& radii) {
    double x0 = std::numeric_limits<double>::max(), y0 = x0, x1 = -x0, y1 = -x0;
    for (size_t k = 0; k < points.size(); ++k) {
      x0 = std::min(x0, points[k].x - radii[k]);
      y0 = std::min(y0, points[k].y - radii[k]);
      x1 = std::max(x1, points[k].x + radii[k]);
      y1 = std::max(y1, points[k].y + radii[k]);
    }
    x0_ = x0;
    y0_ = y0;
    cell_ = std::max({kMinCellPx, (x1 - x0) / kMaxCellsPerSide, (y1 - y0) / kMaxCellsPerSide});
    nx_ = static_cast<int>((x1 - x0) / cell_) + 1;
    ny_ = static_cast<int>((y1 - y0) / cell_) + 1;
    cells_.resize(static_cast<size_t>(nx_) * ny_);
    for (size_t k = 0; k < points.size(); ++k) {
      const Vec2& p = points[k];
      forCells(p.x - radii[k], p.y - radii[k], p.x + radii[k], p.y + radii[k],
               [&](std::vector<int>& cell) { cell.push_back(static_cast<int>(k)); });
    }
  }

  // The rectangle the cells cover: a triangle whose box misses it visits no cell.
  void extent(double* xa, double* ya, double* xb, double* yb) const {
    *xa = x0_;
    *ya = y0_;
    *xb = x0_ + nx_ * cell_;
    *yb = y0_ + ny_ * cell_;
  }

  // Calls `visit` with every cell overlapping the box (clipped to the grid).
  template <typename Visit>
  void forCells(double xa, double ya, double xb, double yb, Visit&& visit) {
    const int i0 = std::max(0, static_cast<int>(std::floor((xa - x0_) / cell_)));
    const int j0 = std::max(0, static_cast<int>(std::floor((ya - y0_) / cell_)));
    const int i1 = std::min(nx_ - 1, static_cast<int>(std::floor((xb - x0_) / cell_)));
    const int j1 = std::min(ny_ - 1, static_cast<int>(std::floor((yb - y0_) / cell_)));
    for (int j = j0; j <= j1; ++j) {
      for (int i = i0; i <= i1; ++i) visit(cells_[static_cast<size_t>(j) * nx_ + i]);
    }
  }

 private:
  double x0_ = 0, y0_ = 0, cell_ = kMinCellPx;
  int nx_ = 1, ny_ = 1;
  std::vector<std::vector<int>> cells_;
};

// Per thread: the smallest distance found for each point, and whether a triangle covers it.
struct Nearest {
  std::vector<double> distance;
  std::vector<char> covered;
};

// The triangles in front of the near plane filed by the image-plane cell of their box's lower
// corner (cells of kBucketPx), so that a batch of points visits only the triangles that can
// reach its grid: the visits, and so the distances, are those of a pass over every triangle
// (a triangle whose box misses the points' grid visits none of its cells), at the cost of one
// pass for the whole query instead of one per batch. Triangles wider or taller than kBucketPx
// are listed apart and always visited.
class TriangleBuckets {
 public:
  static constexpr double kBucketPx = 32;

  void build(const tessellate::TriangleMesh& mesh, const std::vector<Vec2>& projected,
             const std::vector<char>& inFront) {
    const size_t triangles = mesh.indices.size() / 3;
    // The lower corner of triangle t's box; whether it is small (false: large, NaN or behind).
    auto lowerCorner = [&](size_t t, double* xa, double* ya) {
      const uint32_t* c = &mesh.indices[3 * t];
      if (!inFront[c[0]] || !inFront[c[1]] || !inFront[c[2]]) return false;
      const Vec2 &a = projected[c[0]], &b = projected[c[1]], &d = projected[c[2]];
      *xa = std::min({a.x, b.x, d.x});
      *ya = std::min({a.y, b.y, d.y});
      const double xb = std::max({a.x, b.x, d.x}), yb = std::max({a.y, b.y, d.y});
      return xb - *xa <= kBucketPx && yb - *ya <= kBucketPx;
    };
    double x0 = std::numeric_limits<double>::max(), y0 = x0, x1 = -x0, y1 = -x0;
    for (size_t t = 0; t < triangles; ++t) {
      double xa, ya;
      if (!lowerCorner(t, &xa, &ya)) {
        const uint32_t* c = &mesh.indices[3 * t];
        if (inFront[c[0]] && inFront[c[1]] && inFront[c[2]]) {
          large_.push_back(static_cast<uint32_t>(t));
        }
        continue;
      }
      x0 = std::min(x0, xa);
      y0 = std::min(y0, ya);
      x1 = std::max(x1, xa);
      y1 = std::max(y1, ya);
      small_.push_back(static_cast<uint32_t>(t));
    }
    if (small_.empty()) return;
    x0_ = x0;
    y0_ = y0;
    nx_ = static_cast<int>((x1 - x0) / kBucketPx) + 1;
    ny_ = static_cast<int>((y1 - y0) / kBucketPx) + 1;
    // Counting sort of the small triangles by bucket (ascending triangle order within one).
    start_.assign(static_cast<size_t>(nx_) * ny_ + 1, 0);
    std::vector<uint32_t> bucketOf(small_.size());
    for (size_t k = 0; k < small_.size(); ++k) {
      double xa, ya;
      lowerCorner(small_[k], &xa, &ya);
      bucketOf[k] = static_cast<uint32_t>(bucket(xa, ya));
      ++start_[bucketOf[k] + 1];
    }
    for (size_t b = 1; b < start_.size(); ++b) start_[b] += start_[b - 1];
    std::vector<uint32_t> sorted(small_.size());
    std::vector<uint32_t> next(start_.begin(), start_.end() - 1);
    for (size_t k = 0; k < small_.size(); ++k) sorted[next[bucketOf[k]]++] = small_[k];
    small_ = std::move(sorted);
  }

  // Every triangle whose box can meet [xa, xb] x [ya, yb] (and some that cannot).
  std::vector<uint32_t> near(double xa, double ya, double xb, double yb) const {
    std::vector<uint32_t> out = large_;
    if (small_.empty()) return out;
    // A small triangle's lower corner lies at most kBucketPx below-left of any point of it.
    const int i0 = std::max(0, static_cast<int>(std::floor((xa - kBucketPx - x0_) / kBucketPx)));
    const int j0 = std::max(0, static_cast<int>(std::floor((ya - kBucketPx - y0_) / kBucketPx)));
    const int i1 = std::min(nx_ - 1, static_cast<int>(std::floor((xb - x0_) / kBucketPx)));
    const int j1 = std::min(ny_ - 1, static_cast<int>(std::floor((yb - y0_) / kBucketPx)));
    for (int j = j0; j <= j1; ++j) {
      if (i0 > i1) break;
      const size_t first = start_[static_cast<size_t>(j) * nx_ + i0];
      const size_t last = start_[static_cast<size_t>(j) * nx_ + i1 + 1];
      out.insert(out.end(), small_.begin() + first, small_.begin() + last);
    }
    return out;
  }

 private:
  size_t bucket(double x, double y) const {
    const int i = std::min(nx_ - 1, static_cast<int>((x - x0_) / kBucketPx));
    const int j = std::min(ny_ - 1, static_cast<int>((y - y0_) / kBucketPx));
    return static_cast<size_t>(j) * nx_ + i;
  }

  double x0_ = 0, y0_ = 0;
  int nx_ = 0, ny_ = 0;
  std::vector<uint32_t> small_, large_;
  std::vector<size_t> start_;  // small_[start_[b], start_[b + 1]) lie in bucket b
};

// The mesh's vertices in the image plane and its triangles' buckets, made on the query's first
// call and kept for the next (lowerLargestFirst calls it once per batch).
struct ProjectedMesh {
  const tessellate::TriangleMesh& mesh;
  const Camera& camera;
  const CancelToken& cancel;
  std::once_flag once;
  std::vector<Vec2> projected;
  std::vector<char> inFront;  // in front of the near plane
  // Some triangle reaches behind it: left out, it could leave a point it covers looking
  // uncovered, so gaps are not searched for (coverage_distance.h).
  bool partlyBehind = false;
  TriangleBuckets buckets;

  void project() {
    const size_t vertexCount = mesh.positions.size();
    projected.resize(vertexCount);
    inFront.resize(vertexCount);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, vertexCount, kTriangleGrain),
                      [&](const tbb::blocked_range<size_t>& range) {
                        for (size_t v = range.begin(); v < range.end(); ++v) {
                          const Vec3f& q = mesh.positions[v];
                          const Vec3 p = camera.project(Vec3{q.x, q.y, q.z});
                          projected[v] = {p.x, p.y};
                          inFront[v] = p.z > camera.nearPlane();
                        }
                      });
    buckets.build(mesh, projected, inFront);
    for (size_t i = 0; i < mesh.indices.size() && !partlyBehind; ++i) {
      partlyBehind = !inFront[mesh.indices[i]];
    }
  }
};

// The search for gaps narrower than the samples around one covered point.
//
// The coverage's edge lies on the triangles' edges, and only on those that are not between two
// triangles on either side of them: a mesh border, or a fold where both triangles lie on one
// side (a contour). Each such edge, moved a hair off its triangles, is clipped against every
// other triangle near the point; what no triangle covers is uncovered, and its nearest point
// is a point of the coverage's edge.
class GapSearch {
 public:
  // The narrowest gap looked for (output px).
  static constexpr double kGapPx = 1e-3;

  GapSearch(const ProjectedMesh& projection, Vec2 p, double radius) : p_(p) {
    const tessellate::TriangleMesh& mesh = projection.mesh;
    for (uint32_t t :
         projection.buckets.near(p.x - radius, p.y - radius, p.x + radius, p.y + radius)) {
      const uint32_t* c = &mesh.indices[3 * size_t{t}];
      const Vec2 &a = projection.projected[c[0]], &b = projection.projected[c[1]],
                 &d = projection.projected[c[2]];
      if (pointTriangleDistance(p, a, b, d) < radius) triangles_.push_back({a, b, d});
    }
  }

  // The distance from the point to the nearest point no triangle covers, when below `bound`;
  // else `bound`.
  double nearestUncovered(double bound) const {
    double best = bound;
    for (const BorderEdge& e : borderEdges()) {
      if (pointSegmentDistance(p_, e.a, e.b) >= best) continue;
      for (double side : {-1.0, 1.0}) {
        if (e.side != 0 && side != e.side) continue;
        best = std::min(best, nearestUncoveredOn(e, side));
      }
    }
    return best;
  }

 private:
  struct Triangle {
    Vec2 a, b, c;
  };
  // An edge that can bound the coverage, and the side away from its triangles (+1 left of a->b,
  // -1 right; 0: both sides are searched, for edges of three or more triangles or flat ones).
  struct BorderEdge {
    Vec2 a, b;
    double side;
  };

  static bool before(const Vec2& u, const Vec2& v) {
    return u.x < v.x || (u.x == v.x && u.y < v.y);
  }

  // The triangles' edges that are not shared by exactly two triangles on opposite sides. Edges
  // are matched by their endpoints' positions, so that meshes which repeat vertices along patch
  // seams (at the same positions: crack-free) are matched across them.
  std::vector<BorderEdge> borderEdges() const {
    struct HalfEdge {
      Vec2 a, b;    // a before b
      double side;  // sign of the triangle's third corner, left of a->b positive
    };
    std::vector<HalfEdge> halves;
    halves.reserve(3 * triangles_.size());
    for (const Triangle& t : triangles_) {
      const Vec2 corners[3] = {t.a, t.b, t.c};
      for (int k = 0; k < 3; ++k) {
        Vec2 u = corners[k], v = corners[(k + 1) % 3];
        if (before(v, u)) std::swap(u, v);
        const double area = cross(u, v, corners[(k + 2) % 3]);
        halves.push_back({u, v, area > 0 ? 1.0 : area < 0 ? -1.0 : 0.0});
      }
    }
    auto key = [](const HalfEdge& h) { return std::tie(h.a.x, h.a.y, h.b.x, h.b.y); };
    std::sort(halves.begin(), halves.end(),
              [&](const HalfEdge& l, const HalfEdge& r) { return key(l) < key(r); });
    std::vector<BorderEdge> edges;
    for (size_t i = 0; i < halves.size();) {
      size_t j = i + 1;
      while (j < halves.size() && key(halves[j]) == key(halves[i])) ++j;
      const HalfEdge& h = halves[i];
      if (j - i == 1 && h.side != 0) {
        edges.push_back({h.a, h.b, -h.side});
      } else if (j - i == 2 && h.side != 0 && h.side == halves[i + 1].side) {
        edges.push_back({h.a, h.b, -h.side});  // a fold: both triangles on one side
      } else if (j - i != 2 || h.side * halves[i + 1].side >= 0) {
        edges.push_back({h.a, h.b, 0});
      }
      i = j;
    }
    return edges;
  }

  // The distance from the point to the nearest point of edge `e`, moved kGapPx to `side`, that
  // no triangle covers (infinity when every point is covered). Covered runs less than kGapPx
  // apart are one: the positions are floats, and a gap that narrow is rounding, not surface.
  double nearestUncoveredOn(const BorderEdge& e, double side) const {
    const double dx = e.b.x - e.a.x, dy = e.b.y - e.a.y;
    const double length = std::hypot(dx, dy);
    if (length == 0) return std::numeric_limits<double>::infinity();
    // The left normal of a->b is (-dy, dx).
    const Vec2 a{e.a.x - side * kGapPx * dy / length, e.a.y + side * kGapPx * dx / length};
    const Vec2 b{a.x + dx, a.y + dy};
    std::vector<std::pair<double, double>> covered;
    for (const Triangle& t : triangles_) {
      double t0 = 0, t1 = 1;
      if (clipToTriangle(a, b, t, t0, t1)) covered.push_back({t0, t1});
    }
    std::sort(covered.begin(), covered.end());
    // The foot of the point on the edge, and the covered run [lo, hi] holding it, if any.
    const double foot =
        std::clamp(((p_.x - a.x) * dx + (p_.y - a.y) * dy) / (length * length), 0.0, 1.0);
    double lo = 0, hi = -1;
    for (auto [t0, t1] : covered) {
      if (t0 > hi + kGapPx / length) {  // a new run
        if (lo <= foot && foot <= hi) break;
        lo = t0;
      }
      hi = std::max(hi, t1);
    }
    const bool inside = lo <= foot && foot <= hi;
    auto at = [&](double t) { return std::hypot(p_.x - (a.x + t * dx), p_.y - (a.y + t * dy)); };
    if (!inside) return at(foot);
    double best = std::numeric_limits<double>::infinity();
    if (lo > 0) best = std::min(best, at(lo));
    if (hi < 1) best = std::min(best, at(hi));
    return best;
  }

  // Clips the parameters [t0, t1] of segment a->b to the closed triangle; false when empty.
  static bool clipToTriangle(const Vec2& a, const Vec2& b, const Triangle& t, double& t0,
                             double& t1) {
    const double area = cross(t.a, t.b, t.c);
    if (area == 0) return false;
    const double s = area > 0 ? 1 : -1;
    const Vec2 corners[3] = {t.a, t.b, t.c};
    for (int k = 0; k < 3; ++k) {
      // Inside edge k where s * cross(u, v, x) >= 0, linear along the segment.
      const double fa = s * cross(corners[k], corners[(k + 1) % 3], a);
      const double fb = s * cross(corners[k], corners[(k + 1) % 3], b);
      if (fa < 0 && fb < 0) return false;
      if (fa < 0) t0 = std::max(t0, fa / (fa - fb));
      if (fb < 0) t1 = std::min(t1, fa / (fa - fb));
      if (t0 > t1) return false;
    }
    return true;
  }

  Vec2 p_;
  std::vector<Triangle> triangles_;
};

// Gaps narrower than the samples are searched for only this far from a point: a search gathers
// every triangle within it.
constexpr double kMaxGapSearchPx = 8;

void lowerToMeshDistances(ProjectedMesh& projection, const std::vector<Vec2>& points,
                          std::vector<double>& distances) {
  if (points.empty()) return;
  std::call_once(projection.once, [&] { projection.project(); });
  const tessellate::TriangleMesh& mesh = projection.mesh;
  const CancelToken& cancel = projection.cancel;
  const std::vector<Vec2>& projected = projection.projected;
  const std::vector<char>& inFront = projection.inFront;
  cancel.check();

  PointGrid grid(points, distances);
  tbb::enumerable_thread_specific<Nearest> nearest([&] {
    return Nearest{distances, std::vector<char>(points.size(), 0)};
  });
  double gx0, gy0, gx1, gy1;
  grid.extent(&gx0, &gy0, &gx1, &gy1);
  const std::vector<uint32_t> candidates = projection.buckets.near(gx0, gy0, gx1, gy1);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, candidates.size(), kTriangleGrain),
                    [&](const tbb::blocked_range<size_t>& range) {
                      if (cancel.expired()) return;
                      Nearest& mine = nearest.local();
                      for (size_t i = range.begin(); i < range.end(); ++i) {
                        const uint32_t* corner = &mesh.indices[3 * size_t{candidates[i]}];
                        if (!inFront[corner[0]] || !inFront[corner[1]] || !inFront[corner[2]]) {
                          continue;
                        }
                        const Vec2 &a = projected[corner[0]], &b = projected[corner[1]],
                                   &c = projected[corner[2]];
                        const double xa = std::min({a.x, b.x, c.x}), xb = std::max({a.x, b.x, c.x});
                        const double ya = std::min({a.y, b.y, c.y}), yb = std::max({a.y, b.y, c.y});
                        grid.forCells(xa, ya, xb, yb, [&](const std::vector<int>& cell) {
                          for (int k : cell) {
                            const Vec2& p = points[k];
                            // The box's distance bounds the triangle's from below.
                            const double bx = std::max({xa - p.x, 0.0, p.x - xb});
                            const double by = std::max({ya - p.y, 0.0, p.y - yb});
                            if (std::hypot(bx, by) >= mine.distance[k] && !(bx == 0 && by == 0)) {
                              continue;
                            }
                            const double d = pointTriangleDistance(p, a, b, c);
                            if (d == 0) mine.covered[k] = 1;
                            mine.distance[k] = std::min(mine.distance[k], d);
                          }
                        });
                      }
                    });
  cancel.check();
  std::vector<size_t> coveredPoints;
  for (size_t k = 0; k < points.size(); ++k) {
    double lowest = distances[k];
    bool covered = false;
    for (const Nearest& n : nearest) {
      lowest = std::min(lowest, n.distance[k]);
      covered = covered || n.covered[k];
    }
    if (!covered) {
      distances[k] = lowest;
    } else if (!projection.partlyBehind) {
      coveredPoints.push_back(k);
    }
  }
  // A covered point's sampled distance is to the other outline's samples, which miss a gap or
  // slit narrower than they are: measure it to the nearest point the triangles leave uncovered.
  tbb::parallel_for(tbb::blocked_range<size_t>(0, coveredPoints.size(), 1),
                    [&](const tbb::blocked_range<size_t>& range) {
                      for (size_t i = range.begin(); i < range.end(); ++i) {
                        if (cancel.expired()) return;
                        const size_t k = coveredPoints[i];
                        const double radius = std::min(distances[k], kMaxGapSearchPx);
                        const double gap =
                            GapSearch(projection, points[k], radius).nearestUncovered(radius);
                        if (gap < radius) distances[k] = gap;
                      }
                    });
  cancel.check();
}

}  // namespace

double pointSegmentDistance(const Vec2& p, const Vec2& a, const Vec2& b) {
  const double dx = b.x - a.x, dy = b.y - a.y;
  const double length2 = dx * dx + dy * dy;
  double t = length2 > 0 ? ((p.x - a.x) * dx + (p.y - a.y) * dy) / length2 : 0;
  t = std::clamp(t, 0.0, 1.0);
  return std::hypot(p.x - (a.x + t * dx), p.y - (a.y + t * dy));
}

double pointTriangleDistance(const Vec2& p, const Vec2& a, const Vec2& b, const Vec2& c) {
  const double area = cross(a, b, c);
  if (area != 0) {
    // Inside when p is on the inner side of all three edges, whatever the winding.
    const double s = area > 0 ? 1 : -1;
    if (s * cross(a, b, p) >= 0 && s * cross(b, c, p) >= 0 && s * cross(c, a, p) >= 0) return 0;
  }
  return std::min({pointSegmentDistance(p, a, b), pointSegmentDistance(p, b, c),
                   pointSegmentDistance(p, c, a)});
}

CoverageDistanceQuery meshCoverageDistance(const tessellate::TriangleMesh& mesh,
                                           const Camera& camera, const CancelToken& cancel) {
  auto projection = std::shared_ptr<ProjectedMesh>(
      new ProjectedMesh{mesh, camera, cancel, {}, {}, {}, false, {}});
  return [projection](const std::vector<Vec2>& points, std::vector<double>& distances) {
    lowerToMeshDistances(*projection, points, distances);
  };
}

void lowerLargestFirst(const CoverageDistanceQuery& query, const std::vector<Vec2>& points,
                       std::vector<double>& distances) {
  std::vector<size_t> order(points.size());
  for (size_t k = 0; k < order.size(); ++k) order[k] = k;
  std::sort(order.begin(), order.end(),
            [&](size_t a, size_t b) { return distances[a] > distances[b]; });
  double measuredMax = 0;
  size_t done = 0, batch = kFirstBatch;
  std::vector<Vec2> batchPoints;
  std::vector<double> batchDistances;
  while (done < order.size() && distances[order[done]] > measuredMax) {
    const size_t end = std::min(order.size(), done + batch);
    batchPoints.clear();
    batchDistances.clear();
    for (size_t i = done; i < end; ++i) {
      batchPoints.push_back(points[order[i]]);
      batchDistances.push_back(distances[order[i]]);
    }
    query(batchPoints, batchDistances);
    for (size_t i = done; i < end; ++i) {
      double& d = distances[order[i]];
      d = std::min(d, batchDistances[i - done]);
      measuredMax = std::max(measuredMax, d);
    }
    done = end;
    batch *= 2;
  }
}

}  // namespace limn::render::metrics
