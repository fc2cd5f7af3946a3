// Contour curves chained into polylines across faces, and polylines cut into pieces by
// visibility: hand-made curves for the joining rules, then real limit-surface contours (a
// sphere-like cube, smooth and creased tori) for the invariants a client relies on.
#include "render/silhouette/contour_polylines.h"

#include <gtest/gtest.h>

#include <map>
#include <set>

#include "render/silhouette/presubdivide.h"
#include "render/silhouette/silhouette_mesh.h"
#include "render/subdiv/limit_surface.h"
#include "tests/unit/test_meshes.h"

namespace limn::render::silhouette {
namespace {

Camera testCamera() {
  CameraSpec spec;
  spec.width = 256;
  spec.height = 256;
  Bounds bounds;
  bounds.extend({-5, -5, -5});
  bounds.extend({5, 5, 5});
  return resolveCamera(spec, bounds);
}

// A curve between edge points (fromEdge, 0) and (toEdge, 0) with one sample between them;
// positions are x = edge number so the order along a chain can be read back.
ContourCurve curve(int face, int fromEdge, int toEdge) {
  ContourCurve c;
  c.face = face;
  c.fromEdge = fromEdge;
  c.fromPoint = 0;
  c.toEdge = toEdge;
  c.toPoint = 0;
  auto point = [](double x) { return FacePoint{{x, 0}, {x, 0, 0}, {0, 1, 0}}; };
  c.points = {point(fromEdge), point(0.5 * (fromEdge + toEdge)), point(toEdge)};
  return c;
}

std::vector<double> xs(const ContourPolyline& line) {
  std::vector<double> out;
  for (const PolylinePoint& p : line.points) out.push_back(p.position.x);
  return out;
}

TEST(ChainContourCurves, JoinsCurvesAtSharedEdgePointsReversingWhereNeeded) {
  // 1 -> 2, then a curve stored 3 -> 2 (entered backwards), then 3 -> 4: one open chain.
  std::vector<ContourCurve> curves = {curve(0, 1, 2), curve(1, 3, 2), curve(2, 3, 4)};
  std::vector<ContourPolyline> lines = chainContourCurves(curves, testCamera());
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_FALSE(lines[0].closed);
  EXPECT_EQ(xs(lines[0]), (std::vector<double>{1, 1.5, 2, 2.5, 3, 3.5, 4}));
  EXPECT_EQ(lines[0].curves, (std::vector<int>{0, 1, 2}));
  // Shared points keep the face of the curve that reaches them first.
  EXPECT_EQ(lines[0].points[2].face, 0);
  EXPECT_EQ(lines[0].points[4].face, 1);
  std::vector<bool> edge;
  for (const PolylinePoint& p : lines[0].points) edge.push_back(p.edgePoint);
  EXPECT_EQ(edge, (std::vector<bool>{true, false, true, false, true, false, true}));
}

TEST(ChainContourCurves, StartsOpenChainsAtTheirEndsAndClosesLoops) {
  // An open chain listed from its middle (5 -> 6 before 4 -> 5), and a loop 7 -> 8 -> 9 -> 7.
  std::vector<ContourCurve> curves = {curve(0, 5, 6), curve(1, 7, 8), curve(2, 4, 5),
                                      curve(3, 9, 8), curve(4, 9, 7)};
  std::vector<ContourPolyline> lines = chainContourCurves(curves, testCamera());
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_TRUE(lines[0].closed);  // closed polylines first
  EXPECT_EQ(xs(lines[0]), (std::vector<double>{7, 7.5, 8, 8.5, 9, 8}));
  EXPECT_FALSE(lines[1].closed);
  std::vector<double> open = xs(lines[1]);
  // Either direction is a correct chain; it must run end to end, not start in the middle.
  if (open.front() > open.back()) std::reverse(open.begin(), open.end());
  EXPECT_EQ(open, (std::vector<double>{4, 4.5, 5, 5.5, 6}));
}

TEST(ChainContourCurves, ProjectsEveryPoint) {
  Camera camera = testCamera();
  std::vector<ContourCurve> curves = {curve(0, 1, 2)};
  std::vector<ContourPolyline> lines = chainContourCurves(curves, camera);
  for (const PolylinePoint& p : lines[0].points) {
    Vec3 expected = camera.project(p.position);
    EXPECT_DOUBLE_EQ(p.pixel.x, expected.x);
    EXPECT_DOUBLE_EQ(p.pixel.y, expected.y);
    EXPECT_DOUBLE_EQ(p.pixel.z, expected.z);
  }
}

TEST(SplitPieces, OpenPolylineRunsOfEqualVisibility) {
  ContourPolyline line;
  line.points.resize(6);
  std::vector<bool> visible = {true, true, false, false, false, true};
  std::vector<PolylinePiece> pieces = splitPieces(line, visible);
  ASSERT_EQ(pieces.size(), 3u);
  EXPECT_EQ(pieces[0].start, 0);
  EXPECT_EQ(pieces[0].end, 1);
  EXPECT_TRUE(pieces[0].visible);
  EXPECT_EQ(pieces[1].start, 2);
  EXPECT_EQ(pieces[1].end, 4);
  EXPECT_FALSE(pieces[1].visible);
  EXPECT_EQ(pieces[2].start, 5);
  EXPECT_EQ(pieces[2].end, 5);
}

TEST(SplitPieces, ClosedPolylineIsRotatedSoNoPieceWraps) {
  ContourPolyline line;
  line.closed = true;
  for (int i = 0; i < 6; ++i) line.points.push_back({{double(i), 0, 0}, {}, {}, -1, {}, false});
  // The visible run 4, 5, 0, 1 wraps around the end of the list.
  std::vector<bool> visible = {true, true, false, false, true, true};
  std::vector<PolylinePiece> pieces = splitPieces(line, visible);
  ASSERT_EQ(pieces.size(), 2u);
  EXPECT_EQ(line.points[0].position.x, 2);  // rotated to start where visibility changes
  EXPECT_EQ(visible, (std::vector<bool>{false, false, true, true, true, true}));
  EXPECT_FALSE(pieces[0].visible);
  EXPECT_EQ(pieces[0].end, 1);
  EXPECT_TRUE(pieces[1].visible);
  EXPECT_EQ(pieces[1].start, 2);
  EXPECT_EQ(pieces[1].end, 5);

  std::vector<bool> all(6, true);
  std::vector<PolylinePiece> one = splitPieces(line, all);
  ASSERT_EQ(one.size(), 1u);
  EXPECT_EQ(one[0].end, 5);
}

// ---- Contours of real limit surfaces ----

struct Chained {
  SilhouetteMesh built;
  std::vector<ContourPolyline> lines;
};

Chained chainedContours(const mesh::ControlMesh& control, Vec3 eye, CurveMode mode) {
  subdiv::LimitSurface surface(control);
  CameraSpec spec;
  spec.eye = eye;
  spec.width = spec.height = 512;
  Camera camera = resolveCamera(spec, surface.bounds());
  SilhouetteOptions options;
  options.curves.mode = mode;
  Chained out;
  out.built = buildSilhouetteMesh(surface, camera, options, CancelToken());
  out.lines = chainContourCurves(out.built.curves, camera);
  return out;
}

// Every curve used once; points = curve points - one per junction (a closed chain of k curves
// has k junctions, an open one k - 1); consecutive curves really share their junction point.
void expectConsistentChains(const Chained& c) {
  std::vector<int> uses(c.built.curves.size(), 0);
  size_t curvePoints = 0, junctions = 0, points = 0;
  for (const ContourCurve& curve : c.built.curves) curvePoints += curve.points.size();
  for (const ContourPolyline& line : c.lines) {
    for (int i : line.curves) ++uses[i];
    junctions += line.curves.size() - (line.closed ? 0 : 1);
    points += line.points.size();
    for (size_t k = 0; k < line.points.size(); ++k) {
      bool last = k + 1 == line.points.size();
      if (last && !line.closed) break;
      const Vec3& a = line.points[k].position;
      const Vec3& b = line.points[last ? 0 : k + 1].position;
      // Neighbours along a contour at 512^2 are a few pixels apart, never across the model.
      EXPECT_LT(length(a - b), 0.5) << "a jump inside a polyline at point " << k;
    }
  }
  for (size_t i = 0; i < uses.size(); ++i) EXPECT_EQ(uses[i], 1) << "curve " << i;
  EXPECT_EQ(points, curvePoints - junctions);
}

TEST(ChainContourCurves, SphereLikeCubeHasOneClosedOutline) {
  for (CurveMode mode : {CurveMode::Exact, CurveMode::PN}) {
    Chained c = chainedContours(refineOnce(testing::cube()), {1.2, 2.0, 2.5}, mode);
    ASSERT_GT(c.built.curves.size(), 8u);
    ASSERT_EQ(c.lines.size(), 1u);
    EXPECT_TRUE(c.lines[0].closed);
    expectConsistentChains(c);
    size_t edgePoints = 0;
    for (const PolylinePoint& p : c.lines[0].points) edgePoints += p.edgePoint;
    EXPECT_EQ(edgePoints, c.lines[0].curves.size()) << "one junction per curve on a loop";
  }
}

TEST(ChainContourCurves, ObliqueSmoothTorusHasSeveralClosedLoops) {
  Chained c = chainedContours(testing::torus(12, 8, false), {0.5, 2.0, 1.6}, CurveMode::Exact);
  EXPECT_GT(c.lines.size(), 1u);
  for (const ContourPolyline& line : c.lines) EXPECT_TRUE(line.closed);
  expectConsistentChains(c);
}

TEST(ChainContourCurves, CreasedTorusChainsStayConsistent) {
  // One ring of infinitely sharp edges: contours may end there (open chains).
  Chained c = chainedContours(testing::torus(), {0.5, 2.0, 1.6}, CurveMode::Exact);
  EXPECT_GT(c.lines.size(), 1u);
  expectConsistentChains(c);
  for (const ContourPolyline& line : c.lines) {
    if (line.closed) continue;
    EXPECT_TRUE(line.points.front().edgePoint);
    EXPECT_TRUE(line.points.back().edgePoint);
  }
}

}  // namespace
}  // namespace limn::render::silhouette
