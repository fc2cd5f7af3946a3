#include "render/patches/patch_tessellation.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <iterator>
#include <map>
#include <numbers>
#include <set>
#include <string>
#include <unordered_map>

#include "render/core/error.h"
#include "render/core/parallel.h"
#include "render/tessellate/contour_proximity.h"

namespace limn::render::patches {

PatchDomain PatchDomain::child(int k) const {
  const Vec2 half{0.5, 0.5};
  PatchDomain c = *this;
  c.axisA = {axisA.x * 0.5, axisA.y * 0.5};
  c.axisB = {axisB.x * 0.5, axisB.y * 0.5};
  static constexpr std::array<Vec2, 4> kQuadOffsets = {Vec2{0, 0}, Vec2{0.5, 0}, Vec2{0, 0.5},
                                                       Vec2{0.5, 0.5}};
  static constexpr std::array<Vec2, 3> kTriangleOffsets = {Vec2{0, 0}, Vec2{0.5, 0}, Vec2{0, 0.5}};
  if (triangle && k == 3) {  // corners (1/2, 1/2), (0, 1/2), (1/2, 0)
    c.origin = toPatch(half);
    c.axisA = {-c.axisA.x, -c.axisA.y};
    c.axisB = {-c.axisB.x, -c.axisB.y};
    return c;
  }
  c.origin = toPatch(triangle ? kTriangleOffsets[k] : kQuadOffsets[k]);
  return c;
}

namespace {

constexpr int kPatchesBetweenChecks = 256;
// Patch corners closer than this (times the bounding diagonal) are one vertex: the same limit
// point evaluated on two patches differs by rounding only.
constexpr double kWeldTolerance = 1e-7;
// Neighbouring domains differ by a few levels (Far's by one, the domains a large patch is cut
// into by up to kMaxDomainSplits); splits of an edge are followed this deep.
constexpr int kMaxSplitDepth = 8;
// A patch whose edges want more than maxEdgeFactor segments is cut into 4^k domains (what
// deeper isolation would make of it), k at most this.
constexpr int kMaxDomainSplits = 5;

// Points within `tolerance` of each other, found through a grid of cells of that size.
class Welder {
 public:
  Welder(const std::vector<Vec3>& points, double tolerance)
      : points_(points), cell_(tolerance), tolerance2_(tolerance * tolerance) {}

  int find(const Vec3& p) const {
    const std::array<int64_t, 3> c = cellOf(p);
    for (int dx = -1; dx <= 1; ++dx) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dz = -1; dz <= 1; ++dz) {
          auto it = cells_.find(key({c[0] + dx, c[1] + dy, c[2] + dz}));
          if (it == cells_.end()) continue;
          for (int id : it->second) {
            const Vec3 d = points_[id] - p;
            if (dot(d, d) <= tolerance2_) return id;
          }
        }
      }
    }
    return -1;
  }
  void add(int id) { cells_[key(cellOf(points_[id]))].push_back(id); }

 private:
  std::array<int64_t, 3> cellOf(const Vec3& p) const {
    // Clamped so that a degenerate mesh (a tiny diagonal, hence tiny cells) cannot overflow.
    auto cell = [&](double x) {
      return static_cast<int64_t>(std::clamp(std::floor(x / cell_), -1e18, 1e18));
    };
    return {cell(p.x), cell(p.y), cell(p.z)};
  }
  static uint64_t key(const std::array<int64_t, 3>& c) {
    return (static_cast<uint64_t>(c[0]) * 73856093u) ^ (static_cast<uint64_t>(c[1]) * 19349663u) ^
           (static_cast<uint64_t>(c[2]) * 83492791u);
  }

  const std::vector<Vec3>& points_;
  double cell_, tolerance2_;
  std::unordered_map<uint64_t, std::vector<int>> cells_;
};

Vec2 lerp(Vec2 a, Vec2 b, double t) { return {a.x + (b.x - a.x) * t, a.y + (b.y - a.y) * t}; }

constexpr std::array<Vec2, 4> kQuadCorners = {Vec2{0, 0}, Vec2{1, 0}, Vec2{1, 1}, Vec2{0, 1}};
constexpr std::array<Vec2, 3> kTriangleCorners = {Vec2{0, 0}, Vec2{1, 0}, Vec2{0, 1}};

// Lines across a patch, as three points each: its edges and middle lines (for triangles, the
// lines joining edge midpoints, counted twice as they are half as long).
using Line = std::array<Vec2, 3>;
constexpr std::array<Line, 6> kQuadLines = {Line{Vec2{0, 0}, Vec2{0.5, 0}, Vec2{1, 0}},
                                            Line{Vec2{0, 0.5}, Vec2{0.5, 0.5}, Vec2{1, 0.5}},
                                            Line{Vec2{0, 1}, Vec2{0.5, 1}, Vec2{1, 1}},
                                            Line{Vec2{0, 0}, Vec2{0, 0.5}, Vec2{0, 1}},
                                            Line{Vec2{0.5, 0}, Vec2{0.5, 0.5}, Vec2{0.5, 1}},
                                            Line{Vec2{1, 0}, Vec2{1, 0.5}, Vec2{1, 1}}};
constexpr std::array<Line, 6> kTriangleLines = {
    Line{Vec2{0, 0}, Vec2{0.5, 0}, Vec2{1, 0}},
    Line{Vec2{1, 0}, Vec2{0.5, 0.5}, Vec2{0, 1}},
    Line{Vec2{0, 1}, Vec2{0, 0.5}, Vec2{0, 0}},
    Line{Vec2{0.5, 0}, Vec2{0.25, 0.25}, Vec2{0, 0.5}},
    Line{Vec2{0.5, 0}, Vec2{0.5, 0.25}, Vec2{0.5, 0.5}},
    Line{Vec2{0, 0.5}, Vec2{0.25, 0.5}, Vec2{0.5, 0.5}}};

Vec2 corner(const PatchDomain& domain, int k) {
  return domain.triangle ? kTriangleCorners[k] : kQuadCorners[k];
}

struct Sample {
  Vec3 position, normal;
  VertexSource source;  // where it was evaluated
};

// Position and unit normal at the patch's (s, t); where the derivatives vanish (some end-cap
// corners), the normal a little way towards `centre`.
Sample evaluateAt(const PatchSet& set, const VertexSource& source) {
  const Patch& patch = set.patches()[source.patch];
  Sample out;
  out.source = source;
  Vec3 ds, dt;
  const Vec2 st = source.st, centre = source.towards;
  set.evaluate(patch, st.x, st.y, out.position, ds, dt);
  Vec3 n = cross(ds, dt);
  for (double step = 1e-4; length(n) <= 1e-12 * length(ds) * length(dt) && step < 0.5; step *= 10) {
    Vec3 ignored;
    const Vec2 in = lerp(st, centre, step);
    set.evaluate(patch, in.x, in.y, ignored, ds, dt);
    n = cross(ds, dt);
  }
  const double len = length(n);
  out.normal = len > 0 ? n / len : Vec3{0, 0, 1};
  return out;
}

// The same at the domain's (a, b), towards the domain's centre.
Sample evaluateSample(const PatchSet& set, const PatchDomain& domain, Vec2 ab) {
  const Vec2 centre = domain.toPatch(domain.triangle ? Vec2{1.0 / 3, 1.0 / 3} : Vec2{0.5, 0.5});
  return evaluateAt(set, VertexSource{domain.patch, domain.toPatch(ab), centre});
}

// One piece of a domain edge between two welded vertices, in the domain's coordinates.
struct Piece {
  int from, to;
  Vec2 a, b;
  std::pair<int, int> key() const { return std::minmax(from, to); }
};

// What the inside of one patch becomes. Triangle corners are vertex ids when >= 0, and
// ~k for the patch's k-th interior point.
struct PatchInside {
  std::vector<Vec2> interior;
  std::vector<Sample> samples;
  std::vector<int> triangles;
  std::vector<Vec2> cornerLocal;  // local (s, t) of each triangle corner
};

// One side of the ring: outer points (ids, from corner to corner) zipped to the inner ones.
void zip(const std::vector<int>& outer, const std::vector<Vec2>& outerAt,
         const std::vector<int>& inner, const std::vector<Vec2>& innerAt, PatchInside& out) {
  const size_t m = outer.size() - 1, n = inner.size() - 1;
  size_t a = 0, b = 0;
  auto emit = [&](int i0, Vec2 l0, int i1, Vec2 l1, int i2, Vec2 l2) {
    out.triangles.insert(out.triangles.end(), {i0, i1, i2});
    out.cornerLocal.insert(out.cornerLocal.end(), {l0, l1, l2});
  };
  while (a < m || b < n) {
    const bool advanceOuter = b == n || (a < m && (a + 0.5) / static_cast<double>(m) <=
                                                      (b + 0.5) / static_cast<double>(n));
    if (advanceOuter) {
      emit(outer[a], outerAt[a], outer[a + 1], outerAt[a + 1], inner[b], innerAt[b]);
      ++a;
    } else {
      emit(outer[a], outerAt[a], inner[b + 1], innerAt[b + 1], inner[b], innerAt[b]);
      ++b;
    }
  }
}

// Ring sides: each side's outer points (corner to corner) and their local coordinates.
struct Ring {
  std::vector<std::vector<int>> ids;
  std::vector<std::vector<Vec2>> at;
  int segments(int side) const { return static_cast<int>(ids[side].size()) - 1; }
};

// Each side of the outer ring zipped to the same side of the inner one, given as grid points
// (i, j) that `interiorId` numbers and `at` places.
template <size_t Sides, typename Id, typename At>
void zipRing(const Ring& ring, const std::array<std::vector<std::array<int, 2>>, Sides>& sides,
             const Id& interiorId, const At& at, PatchInside& out) {
  for (size_t k = 0; k < Sides; ++k) {
    std::vector<int> ids;
    std::vector<Vec2> local;
    for (auto [i, j] : sides[k]) {
      ids.push_back(interiorId(i, j));
      local.push_back(at(i, j));
    }
    zip(ring.ids[k], ring.at[k], ids, local, out);
  }
}

void tessellateQuadInside(const Ring& ring, int maxFactor, PatchInside& out) {
  const std::array<int, 4> seg = {ring.segments(0), ring.segments(1), ring.segments(2),
                                  ring.segments(3)};
  if (seg == std::array<int, 4>{1, 1, 1, 1}) {
    const int c0 = ring.ids[0][0], c1 = ring.ids[1][0], c2 = ring.ids[2][0], c3 = ring.ids[3][0];
    out.triangles = {c0, c1, c2, c0, c2, c3};
    out.cornerLocal = {kQuadCorners[0], kQuadCorners[1], kQuadCorners[2],
                       kQuadCorners[0], kQuadCorners[2], kQuadCorners[3]};
    return;
  }
  const int iu = std::clamp(std::max(seg[0], seg[2]), 2, maxFactor);
  const int iv = std::clamp(std::max(seg[1], seg[3]), 2, maxFactor);
  auto interiorId = [&](int i, int j) { return ~((j - 1) * (iu - 1) + (i - 1)); };
  auto at = [&](int i, int j) {
    return Vec2{static_cast<double>(i) / iu, static_cast<double>(j) / iv};
  };
  for (int j = 1; j < iv; ++j) {
    for (int i = 1; i < iu; ++i) out.interior.push_back(at(i, j));
  }
  for (int j = 1; j + 1 < iv; ++j) {
    for (int i = 1; i + 1 < iu; ++i) {
      const int a = interiorId(i, j), b = interiorId(i + 1, j), c = interiorId(i + 1, j + 1),
                d = interiorId(i, j + 1);
      out.triangles.insert(out.triangles.end(), {a, b, c, a, c, d});
      out.cornerLocal.insert(out.cornerLocal.end(), {at(i, j), at(i + 1, j), at(i + 1, j + 1),
                                                     at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  }
  // The inner ring's sides, in the same turning order as the outer ones.
  std::array<std::vector<std::array<int, 2>>, 4> sides;
  for (int i = 1; i < iu; ++i) sides[0].push_back({i, 1});
  for (int j = 1; j < iv; ++j) sides[1].push_back({iu - 1, j});
  for (int i = iu - 1; i >= 1; --i) sides[2].push_back({i, iv - 1});
  for (int j = iv - 1; j >= 1; --j) sides[3].push_back({1, j});
  zipRing(ring, sides, interiorId, at, out);
}

void tessellateTriangleInside(const Ring& ring, int maxFactor, PatchInside& out) {
  const std::array<int, 3> seg = {ring.segments(0), ring.segments(1), ring.segments(2)};
  if (seg == std::array<int, 3>{1, 1, 1}) {
    out.triangles = {ring.ids[0][0], ring.ids[1][0], ring.ids[2][0]};
    out.cornerLocal = {kTriangleCorners[0], kTriangleCorners[1], kTriangleCorners[2]};
    return;
  }
  const int n = std::clamp(std::max({seg[0], seg[1], seg[2]}), 3, maxFactor);
  // Interior points (i, j), i, j >= 1, i + j <= n - 1, numbered row by row.
  std::vector<int> rowStart(n, 0);
  int count = 0;
  for (int j = 1; j <= n - 2; ++j) {
    rowStart[j] = count;
    count += n - 1 - j;
  }
  auto interiorId = [&](int i, int j) { return ~(rowStart[j] + (i - 1)); };
  auto at = [&](int i, int j) {
    return Vec2{static_cast<double>(i) / n, static_cast<double>(j) / n};
  };
  for (int j = 1; j <= n - 2; ++j) {
    for (int i = 1; i + j <= n - 1; ++i) out.interior.push_back(at(i, j));
  }
  for (int j = 1; j <= n - 2; ++j) {
    for (int i = 1; i + j <= n - 2; ++i) {
      out.triangles.insert(out.triangles.end(),
                           {interiorId(i, j), interiorId(i + 1, j), interiorId(i, j + 1)});
      out.cornerLocal.insert(out.cornerLocal.end(), {at(i, j), at(i + 1, j), at(i, j + 1)});
      if (i + j <= n - 3) {
        out.triangles.insert(out.triangles.end(), {interiorId(i + 1, j), interiorId(i + 1, j + 1),
                                                   interiorId(i, j + 1)});
        out.cornerLocal.insert(out.cornerLocal.end(),
                               {at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)});
      }
    }
  }
  std::array<std::vector<std::array<int, 2>>, 3> sides;
  for (int i = 1; i <= n - 2; ++i) sides[0].push_back({i, 1});
  for (int j = 1; j <= n - 2; ++j) sides[1].push_back({n - 1 - j, j});
  for (int j = n - 2; j >= 1; --j) sides[2].push_back({1, j});
  zipRing(ring, sides, interiorId, at, out);
}

// Triangles a domain will make from its sides' segments (checked against the budget before
// evaluating anything inside).
size_t insideTriangles(const PatchDomain& domain, const std::array<int, 4>& sideSegments,
                       int maxFactor) {
  int most = 1, sum = 0;
  for (int k = 0; k < domain.corners(); ++k) {
    most = std::max(most, sideSegments[k]);
    sum += sideSegments[k];
  }
  if (most == 1) return domain.triangle ? 1 : 2;
  const size_t n = std::min(most, maxFactor);
  return (domain.triangle ? n * n : 2 * n * n) + sum;
}

// Thrown by Tessellator::run() when the factors would make more than maxTriangles.
struct OverBudget {
  size_t triangles;
};

class Tessellator {
 public:
  Tessellator(const PatchSet& set, const Camera& camera, const TessellationOptions& options,
              const CancelToken& cancel)
      : set_(set),
        camera_(camera),
        options_(options),
        cancel_(cancel),
        welder_(positions_, kWeldTolerance * std::max(set.controlBounds().diagonal(), 1e-300)) {}

  // The domains, their welded corners and every side's pieces with their segments.
  void plan() {
    chooseCulled();
    makeDomains();
    weldCorners();
    findPieces();
    findCrowdedPieces();
    countSegments();
    if (triangles_ > options_.maxTriangles) throw OverBudget{triangles_};
  }

  TessellationPlan exportPlan() {
    TessellationPlan out;
    out.domains = domains_;
    out.sides.resize(domains_.size());
    for (size_t p = 0; p < domains_.size(); ++p) {
      for (int k = 0; k < domains_[p].corners(); ++k) {
        const Vec2 from = corner(domains_[p], k),
                   to = corner(domains_[p], (k + 1) % domains_[p].corners());
        const Vec2 side{to.x - from.x, to.y - from.y};
        const double length2 = side.x * side.x + side.y * side.y;
        for (const Piece& piece : pieces_[p][k]) {
          const double end =
              ((piece.b.x - from.x) * side.x + (piece.b.y - from.y) * side.y) / length2;
          out.sides[p][k].push_back({end, segments_.at(piece.key())});
        }
        out.sides[p][k].back().end = 1;  // exactly
      }
    }
    out.triangles = triangles_;
    out.stats = finalStats();
    return out;
  }

  // plan(), then every vertex and triangle.
  PatchMesh run() {
    plan();
    const std::vector<PatchDomain>& domains = domains_;
    std::vector<Ring> rings(domains.size());
    for (size_t p = 0; p < domains.size(); ++p) {
      if (p % kPatchesBetweenChecks == 0) cancel_.check();
      rings[p] = ringOf(p);
    }
    std::vector<PatchInside> insides(domains.size());
    parallelFor(domains.size(), 64, [&](size_t begin, size_t end) {
      for (size_t p = begin; p < end; ++p) {
        if (p % kPatchesBetweenChecks == 0) cancel_.check();
        PatchInside& in = insides[p];
        if (domains[p].triangle) {
          tessellateTriangleInside(rings[p], options_.maxEdgeFactor, in);
        } else {
          tessellateQuadInside(rings[p], options_.maxEdgeFactor, in);
        }
        in.samples.reserve(in.interior.size());
        for (const Vec2& ab : in.interior)
          in.samples.push_back(evaluateSample(set_, domains[p], ab));
      }
    });
    cancel_.check();
    return assemble(insides);
  }

 private:
  int addVertex(const Sample& s) {
    positions_.push_back(s.position);
    normals_.push_back(s.normal);
    sources_.push_back(s.source);
    return static_cast<int>(positions_.size()) - 1;
  }

  void weldCorners() {
    const std::vector<PatchDomain>& domains = domains_;
    std::vector<std::array<Sample, 4>> samples(domains.size());
    parallelFor(domains.size(), 256, [&](size_t begin, size_t end) {
      for (size_t p = begin; p < end; ++p) {
        for (int k = 0; k < domains[p].corners(); ++k) {
          samples[p][k] = evaluateSample(set_, domains[p], corner(domains[p], k));
        }
      }
    });
    corners_.assign(domains.size(), {-1, -1, -1, -1});
    for (size_t p = 0; p < domains.size(); ++p) {
      for (int k = 0; k < domains[p].corners(); ++k) {
        int id = welder_.find(samples[p][k].position);
        if (id < 0) {
          id = addVertex(samples[p][k]);
          welder_.add(id);
        }
        corners_[p][k] = id;
      }
    }
  }

  // Per Far patch: 0 drawn, 1 outside the view, 2 facing away.
  void chooseCulled() {
    const std::vector<Patch>& patches = set_.patches();
    patchCulled_.assign(patches.size(), 0);
    if (!options_.cullHidden) return;
    const bool outside = seenFromOutside();
    parallelFor(patches.size(), 256, [&](size_t begin, size_t end) {
      for (size_t p = begin; p < end; ++p) {
        if (outsideTheView(set_, patches[p], camera_)) {
          patchCulled_[p] = 1;
        } else if (const int side = set_.hiddenSide(patches[p].baseFace);
                   outside && side != 0 && facesAwayEverywhere(set_, patches[p], camera_, side)) {
          patchCulled_[p] = 2;
        }
      }
    });
    stats_.patchesOffScreen = std::count(patchCulled_.begin(), patchCulled_.end(), uint8_t{1});
    stats_.patchesCulled = std::count(patchCulled_.begin(), patchCulled_.end(), uint8_t{2});
  }

  // Each patch as one domain, or as 4^k when its edges want more than maxEdgeFactor segments.
  // Judged on projected polylines across the patch (its edges and middle lines), with a margin for
  // the parts that come out longer than half after a cut.
  void makeDomains() {
    const std::vector<Patch>& patches = set_.patches();
    std::vector<int> splits(patches.size(), 0);
    parallelFor(patches.size(), 256, [&](size_t begin, size_t end) {
      for (size_t p = begin; p < end; ++p) {
        if (patchCulled_[p]) continue;
        const PatchDomain whole{static_cast<int>(p), patches[p].triangle};
        double longest = 0;
        for (const auto& line : whole.triangle ? kTriangleLines : kQuadLines) {
          std::array<Vec3, 3> pixel;
          for (int k = 0; k < 3; ++k) {
            pixel[k] = camera_.project(evaluateSample(set_, whole, line[k]).position);
          }
          longest =
              std::max(longest, std::hypot(pixel[0].x - pixel[1].x, pixel[0].y - pixel[1].y) +
                                    std::hypot(pixel[1].x - pixel[2].x, pixel[1].y - pixel[2].y));
        }
        double wanted = longest / options_.dicingRate;
        while (wanted > 0.75 * options_.maxEdgeFactor && splits[p] < kMaxDomainSplits) {
          wanted *= 0.5;
          ++splits[p];
        }
      }
    });
    for (size_t p = 0; p < patches.size(); ++p) {
      if (patchCulled_[p]) continue;
      if (splits[p] > 0) ++stats_.patchesSplit;
      std::vector<PatchDomain> level{PatchDomain{static_cast<int>(p), patches[p].triangle}};
      for (int k = 0; k < splits[p]; ++k) {
        std::vector<PatchDomain> finer;
        for (const PatchDomain& d : level) {
          for (int c = 0; c < 4; ++c) finer.push_back(d.child(c));
        }
        level = std::move(finer);
      }
      domains_.insert(domains_.end(), level.begin(), level.end());
    }
  }

  // The eye outside the surface and nothing of it clipped by the near plane: then every ray
  // meets a front-facing patch before any back-facing one.
  bool seenFromOutside() const {
    const Bounds& b = set_.controlBounds();
    for (int k = 0; k < 8; ++k) {
      const Vec3 c{k & 1 ? b.hi.x : b.lo.x, k & 2 ? b.hi.y : b.lo.y, k & 4 ? b.hi.z : b.lo.z};
      if (camera_.depthOf(c) <= camera_.nearPlane()) return false;
    }
    return true;
  }

  // The edge from corner k to the next, cut where finer neighbours' corners lie on it.
  void splitEdge(const PatchDomain& domain, int from, int to, Vec2 a, Vec2 b, int depth,
                 int maxDepth, std::vector<Piece>& out) {
    if (depth < maxDepth) {
      const Vec2 mid = lerp(a, b, 0.5);
      Vec3 position, ds, dt;
      const Vec2 st = domain.toPatch(mid);
      set_.evaluate(set_.patches()[domain.patch], st.x, st.y, position, ds, dt);
      const int m = welder_.find(position);
      if (m >= 0 && m != from && m != to) {
        splitEdge(domain, from, m, a, mid, depth + 1, maxDepth, out);
        splitEdge(domain, m, to, mid, b, depth + 1, maxDepth, out);
        return;
      }
    }
    out.push_back({from, to, a, b});
  }

  // Segments of one piece: the projected length of its end-midpoint-end polyline over the
  // dicing rate (the midpoint matters along the outline, where the chord is foreshortened but
  // the curve still bulges sideways). A piece crossing the eye plane is as
  // fine as allowed.
  int segmentsOf(const PatchDomain& domain, const Piece& piece) {
    const Vec3 a = camera_.project(positions_[piece.from]);
    const Vec3 b = camera_.project(positions_[piece.to]);
    const Vec3 mid = evaluateSample(set_, domain, lerp(piece.a, piece.b, 0.5)).position;
    const Vec3 m = camera_.project(mid);
    const double projected = std::hypot(a.x - m.x, a.y - m.y) + std::hypot(m.x - b.x, m.y - b.y);
    double wanted = std::ceil(projected / options_.dicingRate);
    if (camera_.projection() == Projection::Perspective) {
      const bool aBehind = a.z <= camera_.nearPlane(), bBehind = b.z <= camera_.nearPlane();
      if (aBehind && bBehind) wanted = 1;
      if (aBehind != bBehind || (m.z <= camera_.nearPlane()) != aBehind) {
        wanted = options_.maxEdgeFactor;
      }
    }
    if (wanted > options_.maxEdgeFactor) ++stats_.clampedEdges;
    if (crowdedPieces_.count(piece.key())) {
      // Finer along a grazing slit, by the length as if it faced the eye (as adaptive dices its
      // contour faces), up to the cap: that is not the asked rate going unmet.
      const double pixels =
          std::max(projected, tessellate::unforeshortenedPixels(camera_, positions_[piece.from],
                                                                mid, positions_[piece.to]));
      wanted = std::max(
          wanted, std::min(std::ceil(pixels * options_.crowdedContourScale / options_.dicingRate),
                           static_cast<double>(options_.maxEdgeFactor)));
    }
    return static_cast<int>(std::clamp(wanted, 1.0, static_cast<double>(options_.maxEdgeFactor)));
  }

  // Every domain side cut where finer neighbours' corners lie on it.
  void findPieces() {
    pieces_.resize(domains_.size());
    for (size_t p = 0; p < domains_.size(); ++p) {
      if (p % kPatchesBetweenChecks == 0) cancel_.check();
      const PatchDomain& domain = domains_[p];
      const int n = domain.corners();
      for (int k = 0; k < n; ++k) {
        // At most maxEdgeFactor pieces per side, so that the side's segments can add up to at
        // most maxEdgeFactor (the plan's promise, and the GPU's hard limit: past
        // GL_MAX_TESS_GEN_LEVEL the GPU tessellator refuses the plan, a 500). Neighbours that
        // differ by Far's one level and up to kMaxDomainSplits cuts make at most 2^6 = 64
        // pieces; more are found only on degenerate surfaces, where patches shrink to points
        // (coincident control points) and the welder matches nearly every midpoint to some
        // corner: such a side is cut less deep until it fits (found by fuzz/engine: a pentagon
        // and a quad sharing three coincident vertices gave a side of 88 pieces).
        for (int depth = kMaxSplitDepth; depth >= 0; --depth) {
          pieces_[p][k].clear();
          splitEdge(domain, corners_[p][k], corners_[p][(k + 1) % n], corner(domain, k),
                    corner(domain, (k + 1) % n), 0, depth, pieces_[p][k]);
          if (static_cast<int>(pieces_[p][k].size()) <= options_.maxEdgeFactor) break;
        }
        if (pieces_[p][k].size() > 1) ++stats_.transitionEdges;
      }
    }
  }

  // The pieces of domains whose contour comes close to another part's contour in the image
  // (tessellate/contour_proximity.h): those are diced crowdedContourScale times finer. A
  // domain's contour is read from the facing at its corners and side midpoints; domains that
  // share a vertex, or a patch, are one part.
  void findCrowdedPieces() {
    crowdedPieces_.clear();
    if (options_.crowdedContourScale <= 1) return;
    std::vector<std::vector<tessellate::ContourPiece>> contour(domains_.size());
    parallelFor(domains_.size(), 256, [&](size_t begin, size_t end) {
      std::vector<Vec2> points;
      std::vector<double> facing;
      for (size_t p = begin; p < end; ++p) {
        if (p % kPatchesBetweenChecks == 0) cancel_.check();
        const PatchDomain& domain = domains_[p];
        points.clear();
        facing.clear();
        bool behind = false;
        auto add = [&](const Vec3& position, const Vec3& normal) {
          const Vec3 pixel = camera_.project(position);
          behind |=
              camera_.projection() == Projection::Perspective && pixel.z <= camera_.nearPlane();
          points.push_back({pixel.x, pixel.y});
          facing.push_back(dot(normal, camera_.viewVector(position)));
        };
        for (int k = 0; k < domain.corners(); ++k) {
          const int id = corners_[p][k];
          add(positions_[id], normals_[id]);
          const Sample mid = evaluateSample(
              set_, domain,
              lerp(corner(domain, k), corner(domain, (k + 1) % domain.corners()), 0.5));
          add(mid.position, mid.normal);
        }
        if (!behind)
          tessellate::appendContourPieces(points, facing, static_cast<int>(p), contour[p]);
      }
    });
    std::vector<tessellate::ContourPiece> pieces;
    for (const auto& c : contour) pieces.insert(pieces.end(), c.begin(), c.end());
    if (pieces.empty()) return;
    auto vertices = [&](int p) {
      std::vector<int> ids;
      for (int k = 0; k < domains_[p].corners(); ++k) {
        for (const Piece& piece : pieces_[p][k]) ids.push_back(piece.from);
      }
      std::sort(ids.begin(), ids.end());
      return ids;
    };
    auto oneApart = [&](int a, int b) {
      if (domains_[a].patch == domains_[b].patch) return true;
      const std::vector<int> va = vertices(a), vb = vertices(b);
      std::vector<int> shared;
      std::set_intersection(va.begin(), va.end(), vb.begin(), vb.end(), std::back_inserter(shared));
      return !shared.empty();
    };
    const std::vector<char> crowded = tessellate::ownersNearAnotherContour(
        pieces, static_cast<int>(domains_.size()), tessellate::kCrowdedContourPx, camera_.width(),
        camera_.height(), oneApart);
    for (size_t p = 0; p < domains_.size(); ++p) {
      if (!crowded[p]) continue;
      ++stats_.crowdedDomains;
      for (int k = 0; k < domains_[p].corners(); ++k) {
        for (const Piece& piece : pieces_[p][k]) crowdedPieces_.insert(piece.key());
      }
    }
  }

  // Segments per piece, computed once per piece by the first domain that has it, so both sides
  // agree. A side cut into P pieces keeps each to maxEdgeFactor / P segments (the cap is the
  // smaller of its two sides'), so no side needs more than maxEdgeFactor in all: the most a
  // hardware tessellator takes per edge.
  void countSegments() {
    std::map<std::pair<int, int>, int> cap;
    for (const auto& sides : pieces_) {
      for (const std::vector<Piece>& side : sides) {
        const int share = std::max(1, options_.maxEdgeFactor / std::max<int>(1, side.size()));
        for (const Piece& piece : side) {
          auto [it, added] = cap.emplace(piece.key(), share);
          if (!added) it->second = std::min(it->second, share);
        }
      }
    }
    triangles_ = 0;
    for (size_t p = 0; p < domains_.size(); ++p) {
      if (p % kPatchesBetweenChecks == 0) cancel_.check();
      std::array<int, 4> sideSegments{0, 0, 0, 0};
      for (int k = 0; k < domains_[p].corners(); ++k) {
        for (const Piece& piece : pieces_[p][k]) {
          auto it = segments_.find(piece.key());
          if (it == segments_.end()) {
            const int segments = std::min(segmentsOf(domains_[p], piece), cap.at(piece.key()));
            it = segments_.emplace(piece.key(), segments).first;
          }
          sideSegments[k] += it->second;
        }
      }
      triangles_ += insideTriangles(domains_[p], sideSegments, options_.maxEdgeFactor);
    }
  }

  // The vertices strictly inside a piece, from `from` towards `to`; made by the first domain
  // that needs them.
  std::vector<int> pieceVertices(const PatchDomain& domain, const Piece& piece) {
    const bool forward = piece.from < piece.to;
    auto it = edgeVertices_.find(piece.key());
    if (it == edgeVertices_.end()) {
      const int segments = segments_.at(piece.key());
      std::vector<int> ids;
      for (int k = 1; k < segments; ++k) {
        const double t = static_cast<double>(k) / segments;
        const Vec2 st = forward ? lerp(piece.a, piece.b, t) : lerp(piece.b, piece.a, t);
        ids.push_back(addVertex(evaluateSample(set_, domain, st)));
      }
      it = edgeVertices_.emplace(piece.key(), std::move(ids)).first;
    }
    std::vector<int> out = it->second;
    if (!forward) std::reverse(out.begin(), out.end());
    return out;
  }

  Ring ringOf(size_t p) {
    const PatchDomain& domain = domains_[p];
    const int n = domain.corners();
    Ring ring;
    ring.ids.resize(n);
    ring.at.resize(n);
    for (int k = 0; k < n; ++k) {
      for (const Piece& piece : pieces_[p][k]) {
        ring.ids[k].push_back(piece.from);
        ring.at[k].push_back(piece.a);
        const std::vector<int> inside = pieceVertices(domain, piece);
        for (size_t i = 0; i < inside.size(); ++i) {
          ring.ids[k].push_back(inside[i]);
          ring.at[k].push_back(lerp(piece.a, piece.b, (i + 1.0) / (inside.size() + 1.0)));
        }
      }
      ring.ids[k].push_back(corners_[p][(k + 1) % n]);
      ring.at[k].push_back(corner(domain, (k + 1) % n));
    }
    return ring;
  }

  TessellationStats finalStats() {
    stats_.patchesDrawn = std::count(patchCulled_.begin(), patchCulled_.end(), uint8_t{0});
    stats_.domains = domains_.size();
    return stats_;
  }

  PatchMesh assemble(std::vector<PatchInside>& insides) {
    const std::vector<Patch>& patches = set_.patches();
    PatchMesh out;
    tessellate::TriangleMesh& mesh = out.mesh;
    for (size_t d = 0; d < domains_.size(); ++d) {
      const int p = domains_[d].patch;
      PatchInside& in = insides[d];
      const int first = static_cast<int>(positions_.size());
      for (const Sample& s : in.samples) addVertex(s);
      for (size_t c = 0; c < in.triangles.size(); ++c) {
        const int id = in.triangles[c];
        mesh.indices.push_back(static_cast<uint32_t>(id >= 0 ? id : first + ~id));
        const Vec2 st = domains_[d].toPatch(in.cornerLocal[c]);
        const Vec2 uv = set_.toFaceUV(patches[p], st.x, st.y);
        mesh.cornerUVs.push_back(Vec2f{static_cast<float>(uv.x), static_cast<float>(uv.y)});
      }
      const size_t count = in.triangles.size() / 3;
      mesh.triangleFaces.insert(mesh.triangleFaces.end(), count, patches[p].baseFace);
      out.trianglePatch.insert(out.trianglePatch.end(), count, static_cast<int32_t>(p));
      in = PatchInside{};
    }
    mesh.positions.reserve(positions_.size());
    mesh.normals.reserve(normals_.size());
    for (size_t i = 0; i < positions_.size(); ++i) {
      mesh.positions.emplace_back(positions_[i]);
      mesh.normals.emplace_back(normals_[i]);
    }
    out.vertexSources = std::move(sources_);
    out.stats = finalStats();
    return out;
  }

  const PatchSet& set_;
  const Camera& camera_;
  const TessellationOptions& options_;
  const CancelToken& cancel_;
  std::vector<Vec3> positions_, normals_;
  std::vector<VertexSource> sources_;
  Welder welder_;
  std::vector<uint8_t> patchCulled_;
  std::vector<PatchDomain> domains_;                       // the drawn patches, whole or cut
  std::vector<std::array<int, 4>> corners_;                // welded corner vertices per domain
  std::vector<std::array<std::vector<Piece>, 4>> pieces_;  // per domain and side
  std::map<std::pair<int, int>, int> segments_;            // per piece, by its welded ends
  std::set<std::pair<int, int>> crowdedPieces_;            // pieces diced finer
  std::map<std::pair<int, int>, std::vector<int>> edgeVertices_;
  size_t triangles_ = 0;
  TessellationStats stats_;
};

}  // namespace

bool outsideTheView(const PatchSet& set, const Patch& patch, const Camera& camera) {
  if (!patch.inHull) return false;
  const std::vector<Vec3> points = set.controlPoints(patch);
  Vec3 centre{0, 0, 0};
  for (const Vec3& q : points) centre += q / static_cast<double>(points.size());
  double radius = 0;
  for (const Vec3& q : points) radius = std::max(radius, length(q - centre));
  radius += set.displacementReach();  // displaced points may lie that far off the hull
  // The sphere in camera space against the four side planes (and, in perspective, the eye
  // plane): outside one of them entirely is outside the view.
  const Vec3 d = centre - camera.eye();
  const double x = dot(d, camera.right()), y = dot(d, camera.trueUp()),
               z = dot(d, camera.forward());
  const double aspect = static_cast<double>(camera.width()) / camera.height();
  if (camera.projection() == Projection::Orthographic) {
    const double halfH = camera.orthoHeight() * 0.5, halfW = halfH * aspect;
    return std::fabs(x) > halfW + radius || std::fabs(y) > halfH + radius;
  }
  if (z < -radius) return true;
  const double tanY = std::tan(camera.fovYDeg() * std::numbers::pi / 360.0), tanX = tanY * aspect;
  auto beyond = [&](double lateral, double tangent) {
    return (std::fabs(lateral) - z * tangent) / std::sqrt(1 + tangent * tangent) > radius;
  };
  return beyond(x, tanX) || beyond(y, tanY);
}

namespace {

// Pairs of a regular patch's points whose differences span its derivatives: a bicubic
// B-spline's derivative along s is a B-spline over the differences of neighbouring points
// along s (and likewise t); a quartic box spline's derivative along a lattice direction is a
// box spline over the differences along that direction. The basis functions are non-negative,
// so each derivative lies in the cone of its differences. Loop's 12 points (Far's order,
// checked against the box spline's corner masks in patches_test) lie in rows of 3, 4, 3 and 2
//     10 11          the patch is the triangle 4 (s, t = 0), 5 (s = 1), 8 (t = 1): s runs
//    7  8  9         along the rows, t to the upper right.
//   3  4  5  6
//    0  1  2
using PointPairs = std::vector<std::pair<int, int>>;
const PointPairs kBSplineAlongS = [] {
  PointPairs out;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 3; ++c) out.push_back({r * 4 + c, r * 4 + c + 1});
  }
  return out;
}();
const PointPairs kBSplineAlongT = [] {
  PointPairs out;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 3; ++c) out.push_back({c * 4 + r, (c + 1) * 4 + r});
  }
  return out;
}();
const PointPairs kBoxSplineAlongS = {{0, 1}, {1, 2}, {3, 4}, {4, 5},
                                     {5, 6}, {7, 8}, {8, 9}, {10, 11}};
const PointPairs kBoxSplineAlongT = {{0, 4}, {1, 5}, {2, 6},  {3, 7},
                                     {4, 8}, {5, 9}, {7, 10}, {8, 11}};

std::vector<Vec3> differences(const std::vector<Vec3>& points, const PointPairs& pairs) {
  std::vector<Vec3> out;
  out.reserve(pairs.size());
  for (auto [from, to] : pairs) out.push_back(points[to] - points[from]);
  return out;
}

}  // namespace

bool facesAwayEverywhere(const PatchSet& set, const Patch& patch, const Camera& camera,
                         int hiddenSide) {
  if (!patch.cullable) return false;
  const std::vector<Vec3> p = set.controlPoints(patch);
  const bool loop = patch.type == OpenSubdiv::Far::PatchDescriptor::LOOP;
  // The normal ds x dt lies in the cone of the cross products of the two sets of differences.
  const std::vector<Vec3> ds = differences(p, loop ? kBoxSplineAlongS : kBSplineAlongS);
  const std::vector<Vec3> dt = differences(p, loop ? kBoxSplineAlongT : kBSplineAlongT);
  // Which way ds x dt turns relative to the surface normal, read at the centre.
  Vec3 position, centreDs, centreDt;
  const double middle = patch.triangle ? 1.0 / 3.0 : 0.5;
  set.evaluate(patch, middle, middle, position, centreDs, centreDt);
  const Vec3 centreNormal = cross(centreDs, centreDt);
  Vec3 sum{0, 0, 0};
  for (const Vec3& a : ds) {
    for (const Vec3& b : dt) sum += cross(a, b);
  }
  const double orientation = (dot(sum, centreNormal) < 0 ? -1.0 : 1.0) * hiddenSide;

  Vec3 centre{0, 0, 0};
  for (const Vec3& q : p) centre += q / static_cast<double>(p.size());
  double radius = 0;
  for (const Vec3& q : p) radius = std::max(radius, length(q - centre));
  const bool perspective = camera.projection() == Projection::Perspective;
  const Vec3 toCentre = perspective ? centre - camera.eye() : camera.forward();
  const double reach = perspective ? radius : 0.0;
  for (const Vec3& a : ds) {
    for (const Vec3& b : dt) {
      const Vec3 n = cross(a, b) * orientation;
      const double len = length(n);
      if (len == 0) continue;  // a zero difference adds nothing to the cone
      // n . (q - eye) > 0 for every q within `reach` of the centre.
      if (dot(n, toCentre) <= len * (reach + 1e-9 * length(toCentre))) return false;
    }
  }
  return true;
}

namespace {

// `make(tessellator)` for a Tessellator with `options`, retried with a coarser dicing rate while
// the factors exceed maxTriangles (when options.fitToBudget); the rate used goes into the stats.
template <typename Make>
auto withinBudget(const PatchSet& patches, const Camera& camera, const TessellationOptions& options,
                  const CancelToken& cancel, Make make) {
  TessellationOptions tried = options;
  for (int attempt = 0;; ++attempt) {
    try {
      Tessellator tessellator(patches, camera, tried, cancel);
      auto out = make(tessellator);
      out.stats.dicingRate = tried.dicingRate;
      return out;
    } catch (const OverBudget& over) {
      if (!options.fitToBudget || attempt == 3) {
        throw InputError(InputError::Kind::LimitExceeded, "maxTriangles",
                         "patches tessellation would make " + std::to_string(over.triangles) +
                             " triangles: exceeds limit maxTriangles " +
                             std::to_string(options.maxTriangles) + " (raise params.dicingRate)");
      }
      // Triangles grow as the square of the segments: coarsen by the square root, and a bit.
      tried.dicingRate *= 1.05 * std::sqrt(static_cast<double>(over.triangles) /
                                           static_cast<double>(options.maxTriangles));
    }
  }
}

}  // namespace

PatchMesh tessellatePatches(const PatchSet& patches, const Camera& camera,
                            const TessellationOptions& options, const CancelToken& cancel) {
  return withinBudget(patches, camera, options, cancel,
                      [](Tessellator& tessellator) { return tessellator.run(); });
}

void reevaluatePatchMesh(const PatchSet& patches, PatchMesh& mesh, const CancelToken& cancel) {
  const std::vector<VertexSource>& sources = mesh.vertexSources;
  if (sources.size() != mesh.mesh.positions.size()) {
    throw std::logic_error("reevaluatePatchMesh: a mesh without its vertex sources");
  }
  parallelFor(sources.size(), 1024, [&](size_t begin, size_t end) {
    cancel.check();
    for (size_t i = begin; i < end; ++i) {
      const Sample s = evaluateAt(patches, sources[i]);
      mesh.mesh.positions[i] = Vec3f(s.position);
      mesh.mesh.normals[i] = Vec3f(s.normal);
    }
  });
  cancel.check();
}

TessellationPlan planPatchTessellation(const PatchSet& patches, const Camera& camera,
                                       const TessellationOptions& options,
                                       const CancelToken& cancel) {
  return withinBudget(patches, camera, options, cancel, [](Tessellator& tessellator) {
    tessellator.plan();
    return tessellator.exportPlan();
  });
}

}  // namespace limn::render::patches
