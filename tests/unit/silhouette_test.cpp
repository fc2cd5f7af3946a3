// The silhouette method's pieces: contour search (including double crossings), curves on the
// limit surface, local re-triangulation, pre-subdivision.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <tuple>
#include <utility>
#include <vector>

#include "render/silhouette/contour_search.h"
#include "render/silhouette/face_triangulation.h"
#include "render/silhouette/presubdivide.h"
#include "render/silhouette/silhouette_mesh.h"
#include "render/subdiv/limit_surface.h"
#include "tests/unit/test_meshes.h"

namespace limn::render::silhouette {
namespace {

using limn::testing::addFace;
using mesh::ControlMesh;

// A strip of quads across a straight ridge along y: heights 0 except the column x = 0 at
// `height`. On the edge from x = -1 to x = 0 the limit slope goes 1/2 -> 2/3 -> 0 (times the
// height), so a view whose ray rises at slope 0.58 sees both ends of that edge in front and its
// middle from behind: two crossings on one edge whose ends agree.
ControlMesh ridge(double height = 1.0) {
  ControlMesh m;
  const int nx = 6, ny = 4;
  for (int j = 0; j <= ny; ++j) {
    for (int i = 0; i <= nx; ++i) {
      double x = i - nx / 2;
      m.points.push_back({x, j - ny / 2.0, x == 0 ? height : 0.0});
    }
  }
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      int a = j * (nx + 1) + i;
      addFace(m, {a, a + 1, a + nx + 2, a + nx + 1});
    }
  }
  return m;
}

// Orthographic view along -x, tilted down so its ray has slope `slope`.
Camera sideView(double slope, int size = 512) {
  Vec3 target{0, 0, 0.3};
  Vec3 dir = normalize(Vec3{-1, 0, -slope});
  return Camera(target - dir * 20.0, target, {0, 0, 1}, 35, Projection::Orthographic, 5.0, size,
                size, 1, 40);
}

CameraSpec obliqueView() {
  CameraSpec spec;
  spec.eye = Vec3{1.2, 2.0, 2.5};
  return spec;
}

// A Catmull-Clark n-gon's domain is a regular polygon mapped onto Bfr's sub-faces: its corners
// and edges land where Bfr puts them, and the map is continuous across the kites' borders (no
// seam inside the face for the contour curves or the triangulation to fall into).
TEST(FaceDomains, PolygonDomainsMatchBfrAndAreContinuous) {
  ControlMesh m;
  m.points = {{0, 0, 0},      {1, 0, 0.2},     {1.4, 0.9, 0}, {0.5, 1.5, 0.3},
              {-0.4, 0.9, 0}, {2.4, 0.2, 0.1}, {0.5, -1.0, 0}};
  testing::addFace(m, {0, 1, 2, 3, 4});  // a pentagon
  testing::addFace(m, {1, 5, 2});        // a triangle
  testing::addFace(m, {0, 6, 1});
  subdiv::LimitSurface surface(m);
  FaceDomains domains(surface);
  const double scale = surface.bounds().diagonal();
  for (int face = 0; face < 3; ++face) {
    const int n = domains.size(face);
    const auto param = surface.parameterization(face);
    for (int k = 0; k < n; ++k) {
      for (double t : {0.0, 0.25, 0.5, 0.75}) {
        double bfr[2];
        param.GetEdgeCoord(k, t, bfr);
        Vec3 expected = surface.position(face, bfr[0], bfr[1]);
        EXPECT_LT(length(domains.position(face, domains.alongEdge(face, k, t)) - expected),
                  1e-9 * scale)
            << "face " << face << " edge " << k << " t " << t;
      }
    }
    Vec2 c = domains.center(face);
    double bfrCenter[2];
    param.GetCenterCoord(bfrCenter);
    EXPECT_LT(
        length(domains.position(face, c) - surface.position(face, bfrCenter[0], bfrCenter[1])),
        1e-9 * scale);
    // Walk circles about the centre (inside the polygon's incircle, radius cos(pi / n) / 2):
    // neighbouring points stay neighbours on the surface.
    for (double fraction : {0.2, 0.6, 0.99}) {
      const double r = fraction * 0.5 * std::cos(M_PI / n);
      Vec3 last = domains.position(face, {c.x + r, c.y});
      for (int i = 1; i <= 2000; ++i) {
        double a = 2 * M_PI * i / 2000;
        Vec2 uv{c.x + r * std::cos(a), c.y + r * std::sin(a)};
        ASSERT_TRUE(domains.contains(face, uv));
        Vec3 p = domains.position(face, uv);
        EXPECT_LT(length(p - last), 0.01 * scale) << "face " << face << " r " << r << " a " << a;
        last = p;
      }
    }
  }
}

TEST(ContourSearch, FindsBothCrossingsOfAnEdgeWhoseEndsAgree) {
  subdiv::LimitSurface surface(ridge());
  Camera camera = sideView(0.58);
  const auto& base = surface.baseLevel();
  for (int samples : {1, 4}) {
    SearchOptions options;
    options.edgeSamples = samples;  // 1: only the slope test can see the pair
    ContourSearch search = searchContour(FaceDomains(surface), camera, options, CancelToken());
    int doubled = 0;
    for (int e = 0; e < base.GetNumEdges(); ++e) {
      auto ends = base.GetEdgeVertices(e);
      Vec3 a = surface.mesh().points[ends[0]], b = surface.mesh().points[ends[1]];
      bool leftFlank =
          std::fabs(a.y - b.y) < 1e-9 && std::min(a.x, b.x) == -1 && std::max(a.x, b.x) == 0;
      if (!leftFlank) continue;
      int crossings = 0;
      for (const EdgePoint& p : search.edgePoints[e]) {
        if (p.sides == 0) continue;  // a point shaping a boundary edge, not a crossing
        ++crossings;
        // On the contour: the limit normal there is perpendicular to the view.
        FaceDomains domains(surface);
        Vec2 uv = edgeUV(domains, base.GetEdgeFaces(e)[0], e, p.t);
        subdiv::LimitSample s = domains.evaluate(base.GetEdgeFaces(e)[0], uv);
        EXPECT_LT(std::fabs(dot(s.normal, camera.forward())), 0.02);
      }
      EXPECT_EQ(crossings, 2) << "edge " << e << " with " << samples << " samples";
      ++doubled;
    }
    EXPECT_EQ(doubled, 5);
    EXPECT_GE(search.stats.doubleCrossings, 5u);
  }
}

// A 5 x 5 grid of unit quads with the four corners of its middle face raised: a bump whose far
// flank, seen from 30 degrees above (looking along +y), turns away from the eye in a small region
// that crosses none of the edges of the face it lies in (face 17: x 2-3, y 3-4).
ControlMesh bump() {
  ControlMesh m;
  for (int j = 0; j < 6; ++j) {
    for (int i = 0; i < 6; ++i) {
      const bool raised = (i == 2 || i == 3) && (j == 2 || j == 3);
      m.points.push_back({static_cast<double>(i), static_cast<double>(j), raised ? 0.8 : 0.0});
    }
  }
  for (int j = 0; j < 5; ++j) {
    for (int i = 0; i < 5; ++i) {
      const int a = j * 6 + i;
      addFace(m, {a, a + 1, a + 7, a + 6});
    }
  }
  return m;
}

Camera bumpView(double elevationDeg) {
  const double e = elevationDeg * std::acos(-1.0) / 180.0;
  const Vec3 target{2.5, 2.5, 0.4};
  return Camera(target + Vec3{0, -12 * std::cos(e), 12 * std::sin(e)}, target, {0, 0, 1}, 30,
                Projection::Perspective, 0, 256, 256, 1, 40);
}

TEST(ContourSearch, FindsALoopInsideOneFaceAndTessellatesIt) {
  subdiv::LimitSurface surface(bump());
  const FaceDomains domains(surface);
  ContourSearch search = searchContour(domains, bumpView(30), {}, CancelToken());
  ASSERT_EQ(search.loopFaces, std::vector<int>{17});
  EXPECT_EQ(search.stats.interiorLoopFaces, 1u);
  for (int e : surface.baseLevel().GetFaceEdges(17)) EXPECT_TRUE(search.edgePoints[e].empty());
  // g really changes sign inside: the centre faces the eye, the loop does not.
  int away = 0, towards = 0;
  for (int j = 1; j < 16; ++j) {
    for (int i = 1; i < 16; ++i) {
      const subdiv::LimitSample s = domains.evaluate(17, {i / 16.0, j / 16.0});
      (contourFunction(bumpView(30), s.position, s.normal) > 0 ? away : towards) += 1;
    }
  }
  EXPECT_GT(away, 0);
  EXPECT_GT(towards, 0);
  // Drawn as a fine tessellation rather than the face's two triangles.
  SilhouetteOptions options;
  options.cullHidden = false;
  SilhouetteMesh drawn = buildSilhouetteMesh(surface, bumpView(30), options, CancelToken());
  size_t inLoopFace = 0;
  for (int32_t f : drawn.mesh.triangleFaces) inLoopFace += f == 17;
  EXPECT_GE(inLoopFace, 32u);
  // From higher up the whole bump faces the eye: no loop.
  EXPECT_TRUE(searchContour(domains, bumpView(45), {}, CancelToken()).loopFaces.empty());
}

// A gear: two 64-gon caps whose rims (infinitely sharp) follow 16 teeth, and the quads of its
// side. Each cap is flat, so it holds no contour from any view.
ControlMesh gear() {
  ControlMesh m;
  const int n = 64;
  for (int y : {0, 1}) {
    for (int k = 0; k < n; ++k) {
      const double r = (k / 2) % 2 == 0 ? 1.0 : 0.85, a = 2 * M_PI * k / n;
      m.points.push_back({r * std::cos(a), 0.2 * y, -r * std::sin(a)});
    }
  }
  std::vector<int> bottom, top;
  for (int k = 0; k < n; ++k) {
    addFace(m, {k, (k + 1) % n, n + (k + 1) % n, n + k});
    m.creases.push_back({k, (k + 1) % n, 10.0f});
    m.creases.push_back({n + k, n + (k + 1) % n, 10.0f});
    bottom.push_back(n - 1 - k);
    top.push_back(n + k);
  }
  for (const std::vector<int>* cap : {&bottom, &top}) {
    m.faceVertexCounts.push_back(n);
    m.faceVertexIndices.insert(m.faceVertexIndices.end(), cap->begin(), cap->end());
  }
  return m;
}

// At a reflex corner of a flat cap (between two teeth) Bfr's normal at the corner itself is the
// cross product of derivatives that turn by more than 180 degrees: it pointed out of the other
// side of the cap, the edge search saw g change sign along the rim, and the cap's triangulation
// along those false curves spanned the gaps between the teeth (20 px on a scene of gears seen
// from below).
TEST(ContourSearch, AFlatCapWithAConcaveRimHoldsNoContour) {
  subdiv::LimitSurface surface(gear());
  const FaceDomains domains(surface);
  // Below the gear, looking up at its bottom cap.
  const Camera camera({-0.9, -4.0, 1.2}, {0, 0.1, 0}, {0, 1, 0}, 30, Projection::Perspective, 1,
                      1024, 1024, 0.1, 100);
  ContourSearch search = searchContour(domains, camera, {}, CancelToken());
  const int n = 64;
  for (int cap : {n, n + 1}) {
    const FaceBoundary boundary = faceBoundary(domains, search, cap);
    EXPECT_EQ(std::count(boundary.crossing.begin(), boundary.crossing.end(), true), 0)
        << "cap " << cap;
  }
}

TEST(ContourSearch, ExactCurvesLieOnTheContour) {
  for (auto [name, cage] : {std::pair{"cube", limn::testing::cube()},
                            std::pair{"icosahedron", limn::testing::icosahedron()},
                            std::pair{"torus", limn::testing::torus(12, 8, false)}}) {
    subdiv::LimitSurface surface(refineOnce(cage));
    Camera camera = resolveCamera(obliqueView(), surface.bounds());
    SilhouetteMesh result = buildSilhouetteMesh(surface, camera, {}, CancelToken());
    EXPECT_GT(result.curves.size(), 8u) << name;
    EXPECT_EQ(result.stats.oddFaces, 0u) << name;
    EXPECT_EQ(result.stats.unresolvedSamples, 0u) << name;
    for (const ContourCurve& curve : result.curves) {
      for (const FacePoint& p : curve.points) {
        double cosine = dot(p.normal, normalize(camera.viewVector(p.position)));
        EXPECT_LT(std::fabs(cosine), 1e-3) << name << " face " << curve.face;
      }
    }
  }
}

// Every edge of the drawn mesh, keyed by its end positions, is used by exactly two triangles:
// no crack and no T-junction on a closed surface. Hidden triangles are kept for this check;
// leaving them out opens the mesh only behind the contour, which the views test covers.
TEST(SilhouetteMesh, IsWatertightOnClosedMeshes) {
  for (auto [name, cage] : {std::pair{"cube", limn::testing::cube()},
                            std::pair{"icosahedron", limn::testing::icosahedron()},
                            std::pair{"torus", limn::testing::torus(12, 8, true)}}) {
    subdiv::LimitSurface surface(refineOnce(cage));
    Camera camera = resolveCamera(obliqueView(), surface.bounds());
    for (CurveMode mode : {CurveMode::Exact, CurveMode::PN}) {
      SilhouetteOptions options;
      options.curves.mode = mode;
      options.cullHidden = false;
      SilhouetteMesh result = buildSilhouetteMesh(surface, camera, options, CancelToken());
      const auto& m = result.mesh;
      using Key = std::tuple<float, float, float>;
      auto key = [&](uint32_t i) {
        return Key{m.positions[i].x, m.positions[i].y, m.positions[i].z};
      };
      std::map<std::pair<Key, Key>, int> uses;
      for (size_t t = 0; t < m.triangleCount(); ++t) {
        // Triangles of zero area (where a face's parameterisation pinches to a point next to
        // a sharp crease) cover nothing and are left out of the count.
        Vec3 p0 = m.positions[m.indices[3 * t]].toDouble(),
             p1 = m.positions[m.indices[3 * t + 1]].toDouble(),
             p2 = m.positions[m.indices[3 * t + 2]].toDouble();
        if (length(cross(p1 - p0, p2 - p0)) < 1e-12) continue;
        for (int k = 0; k < 3; ++k) {
          Key a = key(m.indices[3 * t + k]), b = key(m.indices[3 * t + (k + 1) % 3]);
          ++uses[std::minmax(a, b)];
        }
      }
      int bad = 0;
      for (const auto& [edge, count] : uses) bad += count != 2;
      EXPECT_EQ(bad, 0) << name;
      EXPECT_GT(result.stats.trianglesAdded, 0u);
      EXPECT_GT(result.stats.contourFaces, 0u);
    }
  }
}

// Outline edges (boundaries, sharp creases at the outline) are shaped by points along their
// limit curve only where it bends: a sharp cube's straight edges need none (one every two
// pixels tripled a piecewise flat model's triangles), a wavy sheet's curved boundary keeps some.
TEST(ContourSearch, OutlineEdgesArePointedOnlyWhereTheyBend) {
  auto shapingPoints = [](const ControlMesh& cage, size_t* outlineEdges) {
    subdiv::LimitSurface surface(cage);
    CameraSpec spec = obliqueView();
    spec.width = spec.height = 1024;
    Camera camera = resolveCamera(spec, surface.bounds());
    SilhouetteMesh result =
        buildSilhouetteMesh(surface, camera, SilhouetteOptions{}, CancelToken());
    *outlineEdges = result.stats.search.outlineEdges;
    size_t points = 0;
    for (const auto& edge : result.search.edgePoints) {
      for (const EdgePoint& p : edge) points += p.sides == 0;
    }
    return points;
  };
  size_t outlineEdges = 0;
  EXPECT_EQ(shapingPoints(limn::testing::sharpCube(), &outlineEdges), 0u);
  EXPECT_GT(outlineEdges, 0u);
  EXPECT_GT(shapingPoints(limn::testing::grid(4, 0.4), &outlineEdges), 0u);
  EXPECT_GT(outlineEdges, 0u);
}

TEST(FaceTriangulation, CoversTheFaceWithStraightRunsKept) {
  // Unit square with two extra points on its bottom edge and a curve from the bottom to the top.
  std::vector<Vec2> uv = {{0, 0},   {0.3, 0}, {0.6, 0},    {1, 0},     {1, 1},
                          {0.5, 1}, {0, 1},   {0.45, 0.3}, {0.55, 0.7}};
  std::vector<std::array<int, 3>> triangles = triangulateFace(uv, 7, {{1, 5, {7, 8}}});
  double area = 0;
  std::vector<int> used(uv.size(), 0);
  for (const auto& t : triangles) {
    double a = 0.5 * ((uv[t[1]].x - uv[t[0]].x) * (uv[t[2]].y - uv[t[0]].y) -
                      (uv[t[1]].y - uv[t[0]].y) * (uv[t[2]].x - uv[t[0]].x));
    EXPECT_GT(a, 0);
    area += a;
    for (int k : t) ++used[k];
  }
  EXPECT_NEAR(area, 1.0, 1e-12);
  for (size_t i = 0; i < uv.size(); ++i) EXPECT_GT(used[i], 0) << "point " << i << " unused";
  // No triangle crosses the curve 1 -> 7 -> 8 -> 5: each lies on one side of it.
}

TEST(FaceTriangulation, CutsRegionsIntoDelaunayTrianglesNotFans) {
  // A contour curve across the top of a quad's domain, sampled densely, as on a bottle's neck:
  // clipped into ears alone, the region below it is a fan of long chords from one corner, each
  // sagging off the surface. Every diagonal inside a region must be locally Delaunay.
  std::vector<Vec2> uv = {{0, 0}, {1, 0}, {1, 0.8}, {1, 1}, {0, 1}, {0, 0.8}};
  CurvePath curve{5, 2, {}};
  for (int i = 1; i < 16; ++i) {
    const double x = i / 16.0;
    curve.interior.push_back(static_cast<int>(uv.size()));
    uv.push_back({x, 0.8 + 0.1 * std::sin(3.14159265358979 * x)});
  }
  std::vector<std::array<int, 3>> triangles = triangulateFace(uv, 6, {curve});
  std::set<std::pair<int, int>> constrained;
  for (int i = 0; i < 6; ++i) constrained.insert(std::minmax(i, (i + 1) % 6));
  std::vector<int> chain{curve.from};
  chain.insert(chain.end(), curve.interior.begin(), curve.interior.end());
  chain.push_back(curve.to);
  for (size_t i = 0; i + 1 < chain.size(); ++i)
    constrained.insert(std::minmax(chain[i], chain[i + 1]));

  double area = 0;
  std::map<std::pair<int, int>, int> opposite;  // directed edge -> the corner across from it
  int mostTriangles = 0;
  std::vector<int> trianglesAt(uv.size(), 0);
  for (const auto& t : triangles) {
    area += 0.5 * ((uv[t[1]].x - uv[t[0]].x) * (uv[t[2]].y - uv[t[0]].y) -
                   (uv[t[1]].y - uv[t[0]].y) * (uv[t[2]].x - uv[t[0]].x));
    for (int k = 0; k < 3; ++k) {
      opposite[{t[k], t[(k + 1) % 3]}] = t[(k + 2) % 3];
      mostTriangles = std::max(mostTriangles, ++trianglesAt[t[k]]);
    }
  }
  EXPECT_NEAR(area, 1.0, 1e-12);
  int diagonals = 0;
  for (const auto& [edge, r] : opposite) {
    auto across = opposite.find({edge.second, edge.first});
    if (across == opposite.end() || constrained.count(std::minmax(edge.first, edge.second)))
      continue;
    ++diagonals;
    const Vec2 &a = uv[edge.first], &b = uv[edge.second], &c = uv[r], &d = uv[across->second];
    // d inside the circle through a, b, c (counter-clockwise) would make the diagonal a-b flip.
    const double ax = a.x - d.x, ay = a.y - d.y, bx = b.x - d.x, by = b.y - d.y;
    const double cx = c.x - d.x, cy = c.y - d.y;
    const double inCircle = (ax * ax + ay * ay) * (bx * cy - cx * by) -
                            (bx * bx + by * by) * (ax * cy - cx * ay) +
                            (cx * cx + cy * cy) * (ax * by - bx * ay);
    EXPECT_LE(inCircle, 1e-12) << "diagonal " << edge.first << "-" << edge.second;
  }
  EXPECT_GT(diagonals, 0);
  // A fan puts all 17 triangles below the curve on one corner.
  EXPECT_LT(mostTriangles, 10);
}

TEST(Presubdivide, KeepsTheLimitSurface) {
  ControlMesh cage = limn::testing::torus(12, 8, true);
  subdiv::LimitSurface coarse(cage);
  subdiv::LimitSurface fine(refineOnce(cage));
  EXPECT_EQ(fine.faceCount(), 4 * coarse.faceCount());
  // Fine vertex v that is a child of coarse vertex v has the same limit position.
  for (int v = 0; v < cage.vertexCount(); ++v) {
    Vec3 a = coarse.controlLimitPositions()[v];
    double best = 1e300;
    for (const Vec3& b : fine.controlLimitPositions()) best = std::min(best, length(a - b));
    EXPECT_LT(best, 1e-6) << "vertex " << v;
  }
  EXPECT_FALSE(presubdivisionReason(cage).empty());
}

}  // namespace
}  // namespace limn::render::silhouette
