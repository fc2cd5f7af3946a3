// Edge tables (render/silhouette/edge_tables.h): the weights made by unit impulses, the gather
// of an edge's support points in canonical order, and agreement with Bfr (LimitSurface) along
// every eligible edge of several meshes, from both of its faces, at every tabulated step.
#include "render/silhouette/edge_tables.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <numeric>
#include <random>
#include <string>

#include "render/silhouette/contour_search.h"
#include "render/subdiv/limit_surface.h"
#include "tests/unit/test_meshes.h"

namespace limn::render::silhouette {
namespace {

namespace Far = OpenSubdiv::Far;
using limn::testing::splitBipyramid;
using limn::testing::splitPrism;
using mesh::ControlMesh;
using mesh::Scheme;

// Tolerances the issue sets: position within 1e-9 of the bounding-box diagonal, normal
// direction within 1e-9 rad.
constexpr double kPositionTolerance = 1e-9;
constexpr double kNormalTolerance = 1e-9;

double angleBetween(const Vec3& a, const Vec3& b) {
  return std::atan2(length(cross(a, b)), dot(a, b));
}

// The same mesh with its points renumbered at random and every face's vertex list rotated:
// the gather must not depend on numbering or on where a face's list starts.
ControlMesh relabelled(const ControlMesh& m, unsigned seed) {
  std::vector<int> order(m.points.size());
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), std::mt19937(seed));
  ControlMesh out = m;
  for (size_t i = 0; i < order.size(); ++i) out.points[order[i]] = m.points[i];
  size_t offset = 0;
  for (size_t f = 0; f < m.faceVertexCounts.size(); ++f) {
    const int size = m.faceVertexCounts[f];
    for (int k = 0; k < size; ++k) {
      out.faceVertexIndices[offset + k] = order[m.faceVertexIndices[offset + (k + f) % size]];
    }
    offset += size;
  }
  for (mesh::Crease& c : out.creases) c = {order[c.v0], order[c.v1], c.sharpness};
  for (mesh::Corner& c : out.corners) c.vertex = order[c.vertex];
  return out;
}

struct Agreement {
  int edges = 0, eligible = 0;
  std::map<int, int> eligibleByValence;
  size_t samples = 0;
  double maxPositionError = 0;  // over the bounding-box diagonal
  double maxNormalAngle = 0;    // radians
};

// Every eligible edge at every step, against LimitSurface::evaluate at the edge's (u, v) in each
// of its two faces (the tables' derivatives are the left face's; the normals must agree with
// the right face's as well).
Agreement compareWithBfr(const ControlMesh& m) {
  subdiv::LimitSurface surface(m);
  const Far::TopologyLevel& level = surface.baseLevel();
  const Bounds box = surface.bounds();
  const double diagonal = length(box.hi - box.lo);
  Agreement out;
  out.edges = level.GetNumEdges();
  for (int e = 0; e < level.GetNumEdges(); ++e) {
    std::optional<EdgeSupport> support = gatherEdgeSupport(level, m.scheme, e);
    if (!support) continue;
    ++out.eligible;
    ++out.eligibleByValence[support->valence];
    Far::ConstIndexArray ends = level.GetEdgeVertices(e);
    for (int face : level.GetEdgeFaces(e)) {
      EXPECT_TRUE(surface.hasLimit(face));
      Far::ConstIndexArray corners = level.GetFaceVertices(face);
      const int i0 =
          static_cast<int>(std::find(corners.begin(), corners.end(), ends[0]) - corners.begin());
      const int i1 =
          static_cast<int>(std::find(corners.begin(), corners.end(), ends[1]) - corners.begin());
      const Vec2 from = surface.cornerUV(face, i0), to = surface.cornerUV(face, i1);
      EdgeCurve curve(*support, m.points, m.scheme);
      for (int k = 0; k <= kEdgeTableSteps; ++k) {
        const double t = static_cast<double>(k) / kEdgeTableSteps;
        subdiv::LimitSample bfr =
            surface.evaluate(face, from.x + (to.x - from.x) * t, from.y + (to.y - from.y) * t);
        EdgeSample table = curve.sample(k);
        const double error = length(table.position - bfr.position) / diagonal;
        const double angle = angleBetween(table.normal, bfr.normal);
        out.maxPositionError = std::max(out.maxPositionError, error);
        out.maxNormalAngle = std::max(out.maxNormalAngle, angle);
        EXPECT_NEAR(length(curve.position(k) - table.position), 0.0, 1e-15 * diagonal);
        ++out.samples;
        if (error > kPositionTolerance || angle > kNormalTolerance) {
          ADD_FAILURE() << "edge " << e << " face " << face << " step " << k << " valence "
                        << support->valence << ": position " << error << ", normal " << angle;
          return out;
        }
      }
    }
  }
  return out;
}

void report(const std::string& name, const Agreement& a) {
  std::printf(
      "%-28s %5d of %5d edges eligible (%4.1f%%), %7zu samples, max position %.2e, "
      "max normal %.2e rad\n",
      name.c_str(), a.eligible, a.edges, 100.0 * a.eligible / std::max(1, a.edges), a.samples,
      a.maxPositionError, a.maxNormalAngle);
}

TEST(EdgeTables, ImpulseResponsesStayInTheSupportAndAreAffine) {
  for (Scheme scheme : {Scheme::CatmullClark, Scheme::Loop}) {
    const EdgeTables& tables = EdgeTables::forScheme(scheme);
    for (int n = kMinTableValence; n <= kMaxTableValence; ++n) {
      const EdgeTable& table = tables.table(n);
      SCOPED_TRACE(std::string(mesh::schemeName(scheme)) + " valence " + std::to_string(n));
      EXPECT_EQ(table.valence(), n);
      EXPECT_EQ(table.supportSize(), scheme == Scheme::Loop ? n + 4 : 2 * n + 4);
      EXPECT_LT(table.leakage(), 1e-13);
      for (int k = 0; k <= kEdgeTableSteps; ++k) {
        const double* w = table.weights(k);
        double position = 0, du = 0, dv = 0, scale = 0;
        for (int j = 0; j < table.supportSize(); ++j) {
          position += w[3 * j];
          du += w[3 * j + 1];
          dv += w[3 * j + 2];
          scale = std::max({scale, std::fabs(w[3 * j + 1]), std::fabs(w[3 * j + 2])});
        }
        // Rounding is that of Bfr's sums over its patch points (weights about 1), even
        // where the derivatives are small (Loop's at a vertex of valence 3 tend to 0).
        EXPECT_NEAR(position, 1.0, 1e-13);
        EXPECT_NEAR(du, 0.0, 1e-13 + 1e-12 * scale);
        EXPECT_NEAR(dv, 0.0, 1e-13 + 1e-12 * scale);
      }
    }
  }
}

TEST(EdgeTables, NotEligibleNearSharpFeaturesBoundariesOrTwoExtraordinaryEnds) {
  auto eligible = [](const ControlMesh& m) {
    subdiv::LimitSurface surface(m);
    int count = 0;
    for (int e = 0; e < surface.baseLevel().GetNumEdges(); ++e) {
      count += gatherEdgeSupport(surface.baseLevel(), m.scheme, e).has_value();
    }
    return count;
  };
  EXPECT_EQ(eligible(limn::testing::cube()), 0);  // valence 3 at both ends of every edge
  EXPECT_EQ(eligible(limn::testing::cube(Scheme::Bilinear)), 0);
  EXPECT_EQ(eligible(limn::testing::icosahedron()), 0);  // valence 5 at both ends
  EXPECT_EQ(eligible(limn::testing::grid(3)), 0);        // every support touches the boundary
  // grid(8): the support of an edge is interior only when both ends are two rings inside.
  EXPECT_GT(eligible(limn::testing::grid(8)), 0);
  EXPECT_LT(eligible(limn::testing::torus(12, 8, true)),
            eligible(limn::testing::torus(12, 8, false)));
  EXPECT_EQ(eligible(limn::testing::sharpCube()), 0);
}

// Catmull-Clark: every valence 3..16 at one end (prisms), and the project's quad meshes.
TEST(EdgeTables, CatmullClarkAgreesWithBfrAlongEveryEligibleEdge) {
  std::map<int, int> byValence;
  for (int n = kMinTableValence; n <= kMaxTableValence; ++n) {
    Agreement a = compareWithBfr(splitPrism(n));
    report("prism " + std::to_string(n), a);
    EXPECT_GT(a.eligibleByValence[n], 0) << n;
    for (auto [valence, count] : a.eligibleByValence) byValence[valence] += count;
  }
  EXPECT_EQ(byValence.size(), static_cast<size_t>(kMaxTableValence - kMinTableValence + 1));

  const std::pair<std::string, ControlMesh> meshes[] = {
      {"torus 40x25", limn::testing::torus(40, 25, false)},
      {"torus 12x8 creased", limn::testing::torus(12, 8, true)},
      {"bumpy ball 1536", limn::testing::bumpyBall(16)},
      {"wavy torus 48x24", limn::testing::wavyTorus()},
      {"pawn 28", limn::testing::pawn()},
      {"grid 10", limn::testing::grid(10)},
      {"bumpy ball relabelled", relabelled(limn::testing::bumpyBall(6), 7)},
      {"prism 7 relabelled", relabelled(splitPrism(7), 11)},
  };
  for (const auto& [name, m] : meshes) {
    SCOPED_TRACE(name);
    Agreement a = compareWithBfr(m);
    report(name, a);
    EXPECT_GT(a.eligible, 0);
  }
  // Mostly regular quad meshes: nearly every edge away from sharp features is eligible.
  Agreement ball = compareWithBfr(limn::testing::bumpyBall(16));
  EXPECT_GT(ball.eligible, 0.95 * ball.edges);
}

// Loop: every valence 3..16 at one end (bipyramids), the icosphere and relabelled meshes.
TEST(EdgeTables, LoopAgreesWithBfrAlongEveryEligibleEdge) {
  std::map<int, int> byValence;
  for (int n = kMinTableValence; n <= kMaxTableValence; ++n) {
    Agreement a = compareWithBfr(splitBipyramid(n));
    report("bipyramid " + std::to_string(n), a);
    EXPECT_GT(a.eligibleByValence[n], 0) << n;
    for (auto [valence, count] : a.eligibleByValence) byValence[valence] += count;
  }
  EXPECT_EQ(byValence.size(), static_cast<size_t>(kMaxTableValence - kMinTableValence + 1));

  const std::pair<std::string, ControlMesh> meshes[] = {
      {"icosphere 3 (Loop)", limn::testing::icosphere(3, Scheme::Loop)},
      {"icosphere 2 (Loop)", limn::testing::icosphere(2, Scheme::Loop)},
      {"icosphere 3 relabelled", relabelled(limn::testing::icosphere(3, Scheme::Loop), 3)},
      {"bipyramid 9 relabelled", relabelled(splitBipyramid(9), 5)},
  };
  for (const auto& [name, m] : meshes) {
    SCOPED_TRACE(name);
    Agreement a = compareWithBfr(m);
    report(name, a);
    EXPECT_GT(a.eligible, 0);
  }
  Agreement sphere = compareWithBfr(limn::testing::icosphere(3, Scheme::Loop));
  EXPECT_GT(sphere.eligible, 0.9 * sphere.edges);
}

// The contour search on the tables (SearchOptions::edgeTables) finds the points it finds on Bfr,
// to rounding, from views all round.
TEST(EdgeTables, ContourSearchFindsTheSamePointsOnTheTables) {
  for (const ControlMesh& m :
       {limn::testing::bumpyBall(8), limn::testing::icosphere(2, Scheme::Loop), splitPrism(9)}) {
    subdiv::LimitSurface surface(m);
    const FaceDomains domains(surface);
    const Bounds box = surface.bounds();
    const double diagonal = length(box.hi - box.lo);
    SearchOptions onBfr, onTables;
    onTables.edgeTables = true;
    for (const Vec3& eye : {Vec3{0.3, 0.4, 4}, Vec3{-3, 1, 1.5}, Vec3{2, -2.5, -1}}) {
      CameraSpec spec;
      spec.eye = eye;
      const Camera camera = resolveCamera(spec, box);
      ContourSearch a = searchContour(domains, camera, onBfr, CancelToken());
      ContourSearch b = searchContour(domains, camera, onTables, CancelToken());
      EXPECT_EQ(a.stats.edgesOnTables, 0u);
      EXPECT_GT(b.stats.edgesOnTables, 0.9 * b.stats.edgesSampled);
      ASSERT_EQ(a.stats.contourPoints, b.stats.contourPoints);
      EXPECT_GT(b.stats.contourPoints, 0u);
      for (size_t e = 0; e < a.edgePoints.size(); ++e) {
        ASSERT_EQ(a.edgePoints[e].size(), b.edgePoints[e].size()) << e;
        for (size_t i = 0; i < a.edgePoints[e].size(); ++i) {
          EXPECT_NEAR(a.edgePoints[e][i].t, b.edgePoints[e][i].t, 1e-12);
          EXPECT_EQ(a.edgePoints[e][i].sides, b.edgePoints[e][i].sides);
          EXPECT_LT(length(a.edgePoints[e][i].position - b.edgePoints[e][i].position),
                    1e-12 * diagonal);
        }
      }
    }
  }
}

}  // namespace
}  // namespace limn::render::silhouette
