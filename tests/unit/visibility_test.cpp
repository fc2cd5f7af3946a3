// Visibility of contour points against the reference surface: a convex outline is seen whole
// (the grazing rays do not hide it, "pn" curves off the surface included), a far blob's outline
// is hidden exactly where a near blob covers it, and a torus seen nearly edge-on hides part of
// its inner outline behind its near tube. The last two are checked against the reference's own
// depth image (its primary rays), an independent path to the same answer, in perspective and
// orthographic views.
#include "render/oracle/visibility.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "render/core/passes.h"
#include "render/oracle/reference.h"
#include "render/silhouette/contour_polylines.h"
#include "render/silhouette/presubdivide.h"
#include "render/silhouette/silhouette_mesh.h"
#include "render/subdiv/limit_surface.h"
#include "tests/unit/test_meshes.h"

namespace limn::render::oracle {
namespace {

using mesh::ControlMesh;
using silhouette::ContourPolyline;
using silhouette::PolylinePoint;

// Two copies of the unit cube, moved by `a` and `b`, in one mesh.
ControlMesh twoCubes(Vec3 a, Vec3 b) {
  ControlMesh one = testing::cube();
  ControlMesh m = one;
  m.points.clear();
  for (const Vec3& p : one.points) m.points.push_back(p + a);
  for (const Vec3& p : one.points) m.points.push_back(p + b);
  for (int i : one.faceVertexIndices) m.faceVertexIndices.push_back(i + 8);
  m.faceVertexCounts.insert(m.faceVertexCounts.end(), one.faceVertexCounts.begin(),
                            one.faceVertexCounts.end());
  return m;
}

struct Contours {
  std::vector<PolylinePoint> points;  // of every polyline
  std::vector<ContourPolyline> lines;
  std::vector<bool> visible;
  VisibilityStats stats;
};

// The silhouette method's contour (on the mesh refined once), then visibility against the
// reference of the same limit surface.
Contours contours(const ControlMesh& control, const Camera& camera,
                  silhouette::CurveMode mode = silhouette::CurveMode::Exact, int searchSteps = 5,
                  double offsetPx = kContourOffsetPx) {
  subdiv::LimitSurface surface(control);
  subdiv::LimitSurface refined(silhouette::refineOnce(control));
  silhouette::SilhouetteOptions options;
  options.curves.mode = mode;
  options.search.searchSteps = searchSteps;
  silhouette::SilhouetteMesh built =
      silhouette::buildSilhouetteMesh(refined, camera, options, CancelToken());
  Contours out;
  out.lines = silhouette::chainContourCurves(built.curves, camera);
  std::vector<VisibilityPoint> queries;
  for (const ContourPolyline& line : out.lines) {
    for (const PolylinePoint& p : line.points) {
      out.points.push_back(p);
      queries.push_back({p.position, p.normal, silhouette::distanceFromSurface(refined, p)});
    }
  }
  VisibilityOptions visibility;
  visibility.offsetPx = offsetPx;
  out.visible = contourVisibility(surface, camera, queries, visibility, CancelToken(), &out.stats);
  if (offsetPx == 0) {  // the naive test aims at the point itself, wherever the curve put it
    for (VisibilityPoint& q : queries) q.slack = 0;
    out.visible =
        contourVisibility(surface, camera, queries, visibility, CancelToken(), &out.stats);
  }
  return out;
}

// Checks each point against the reference's depth image around its pixel: where all 3 x 3
// pixels are covered by surface nearer than the point by more than `gap`, the point must be
// hidden; where none is, visible. Points near an occluder's outline are left alone. Returns
// how many points each rule checked.
std::pair<size_t, size_t> expectAgreesWithReferenceDepth(const ControlMesh& control,
                                                         const Camera& camera, const Contours& c,
                                                         double gap) {
  subdiv::LimitSurface surface(control);
  PassSelection passes;
  passes.depth = true;
  ReferenceResult reference = renderReference(surface, camera, passes, CancelToken());
  const Image* depth = reference.images.find(pass::kDepth);
  EXPECT_NE(depth, nullptr);
  if (!depth) return {0, 0};
  size_t covered = 0, exposed = 0;
  for (size_t i = 0; i < c.points.size(); ++i) {
    const Vec3& px = c.points[i].pixel;
    int cx = static_cast<int>(std::floor(px.x)), cy = static_cast<int>(std::floor(px.y));
    if (cx < 1 || cy < 1 || cx + 1 >= camera.width() || cy + 1 >= camera.height()) continue;
    int nearer = 0;
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        float d = depth->at(cx + dx, cy + dy);
        nearer += d > 0 && d < px.z - gap;
      }
    }
    if (nearer == 9) {
      ++covered;
      EXPECT_FALSE(c.visible[i]) << "point " << i << " at pixel (" << px.x << ", " << px.y
                                 << ") is behind the reference surface";
    } else if (nearer == 0) {
      ++exposed;
      EXPECT_TRUE(c.visible[i]) << "point " << i << " at pixel (" << px.x << ", " << px.y
                                << ") has nothing nearer in the reference";
    }
  }
  return {covered, exposed};
}

Camera camera(Vec3 eye, Vec3 target, int size = 512) {
  return Camera(eye, target, {0, 1, 0}, 35, Projection::Perspective, 1, size, size, 0.1, 100);
}

size_t countHidden(const std::vector<bool>& visible) {
  size_t n = 0;
  for (bool v : visible) n += !v;
  return n;
}

TEST(ContourVisibility, ConvexOutlineIsSeenWhole) {
  Camera view = camera({1.2, 2.0, 2.5}, {0, 0, 0});
  for (auto mode : {silhouette::CurveMode::Exact, silhouette::CurveMode::PN}) {
    for (int steps : {0, 5}) {
      Contours c = contours(testing::cube(), view, mode, steps);
      ASSERT_GT(c.points.size(), 50u);
      EXPECT_EQ(countHidden(c.visible), 0u)
          << (mode == silhouette::CurveMode::PN ? "pn" : "exact") << ", searchSteps " << steps;
      EXPECT_GT(c.stats.triangles, 1000u);
      // The naive test (one ray aimed at the point itself, hits up to the point count) for
      // comparison: grazing rays touch the tessellation near the point.
      Contours naive = contours(testing::cube(), view, mode, steps, 0.0);
      std::printf(
          "convex outline, %s, searchSteps %d: %zu points, hidden: offset rays %zu, "
          "naive ray %zu\n",
          mode == silhouette::CurveMode::PN ? "pn" : "exact", steps, c.points.size(),
          countHidden(c.visible), countHidden(naive.visible));
    }
  }
}

// Winding-number test of a pixel against a closed polyline's projection, and its distance to
// the polyline's segments (pixels).
bool insideProjection(const std::vector<PolylinePoint>& loop, double x, double y) {
  bool inside = false;
  for (size_t i = 0, j = loop.size() - 1; i < loop.size(); j = i++) {
    const Vec3 &a = loop[i].pixel, &b = loop[j].pixel;
    if ((a.y > y) != (b.y > y) && x < (b.x - a.x) * (y - a.y) / (b.y - a.y) + a.x) inside = !inside;
  }
  return inside;
}
double distanceToProjection(const std::vector<PolylinePoint>& loop, double x, double y) {
  double best = 1e300;
  for (size_t i = 0, j = loop.size() - 1; i < loop.size(); j = i++) {
    const Vec3 &a = loop[i].pixel, &b = loop[j].pixel;
    double dx = b.x - a.x, dy = b.y - a.y;
    double t = std::clamp(((x - a.x) * dx + (y - a.y) * dy) / std::max(dx * dx + dy * dy, 1e-30),
                          0.0, 1.0);
    best = std::min(best, std::hypot(a.x + t * dx - x, a.y + t * dy - y));
  }
  return best;
}

TEST(ContourVisibility, FarBlobIsHiddenWhereTheNearOneCoversIt) {
  // Near blob at z = +1.5, far blob at z = -1.5, seen from +z: the near one covers part of the
  // far one's outline.
  Camera view = camera({0, 0.2, 8}, {0, 0, 0});
  Contours c = contours(twoCubes({0.45, 0.1, 1.5}, {0, 0, -1.5}), view);
  std::vector<PolylinePoint> nearLoop;
  for (const ContourPolyline& line : c.lines) {
    ASSERT_TRUE(line.closed);
    if (line.points[0].position.z > 0) nearLoop = line.points;
  }
  ASSERT_EQ(c.lines.size(), 2u);
  ASSERT_FALSE(nearLoop.empty());
  size_t hiddenFar = 0, coveredFar = 0;
  for (size_t i = 0; i < c.points.size(); ++i) {
    const PolylinePoint& p = c.points[i];
    if (p.position.z > 0) {
      EXPECT_TRUE(c.visible[i]) << "the near outline is in front of everything";
      continue;
    }
    bool covered = insideProjection(nearLoop, p.pixel.x, p.pixel.y);
    double margin = distanceToProjection(nearLoop, p.pixel.x, p.pixel.y);
    coveredFar += covered;
    hiddenFar += !c.visible[i];
    if (margin < 1.0) continue;  // at the near outline itself either answer is right
    EXPECT_EQ(c.visible[i], !covered) << "far point at pixel (" << p.pixel.x << ", " << p.pixel.y
                                      << "), " << margin << " px from the near outline";
  }
  EXPECT_GT(coveredFar, 10u) << "the scene must put part of the far outline behind";
  EXPECT_GT(hiddenFar, 10u);
  auto [covered, exposed] =
      expectAgreesWithReferenceDepth(twoCubes({0.45, 0.1, 1.5}, {0, 0, -1.5}), view, c, 0.5);
  EXPECT_GT(covered, 10u);
  EXPECT_GT(exposed, 100u);
  std::printf("two blobs: %zu contour points, %zu of the far outline hidden, %zu covered\n",
              c.points.size(), hiddenFar, coveredFar);
}

TEST(ContourVisibility, OrthographicRaysRunAlongTheViewDirection) {
  // The same two blobs seen orthographically: the near one no longer looks larger, so move it
  // to cover part of the far one's outline.
  Camera view({0, 0.2, 8}, {0, 0, 0}, {0, 1, 0}, 35, Projection::Orthographic, 3.0, 512, 512, 0.1,
              100);
  ControlMesh blobs = twoCubes({0.35, 0.1, 1.5}, {0, 0, -1.5});
  Contours c = contours(blobs, view);
  ASSERT_EQ(c.lines.size(), 2u);
  size_t hiddenNear = 0, hiddenFar = 0;
  for (size_t i = 0; i < c.points.size(); ++i) {
    (c.points[i].position.z > 0 ? hiddenNear : hiddenFar) += !c.visible[i];
  }
  EXPECT_EQ(hiddenNear, 0u);
  EXPECT_GT(hiddenFar, 10u);
  auto [covered, exposed] = expectAgreesWithReferenceDepth(blobs, view, c, 0.5);
  EXPECT_GT(covered, 10u);
  EXPECT_GT(exposed, 100u);
}

TEST(ContourVisibility, NearlyEdgeOnTorusHidesPartOfItsInnerOutline) {
  // Smooth torus in the xy plane seen from a low angle: the inner rim of the far side of the
  // hole passes behind the near tube.
  Camera view = camera({0, -4.0, 1.1}, {0, 0, 0});
  Contours c = contours(testing::torus(24, 12, false), view);
  size_t hidden = countHidden(c.visible);
  EXPECT_GT(hidden, 5u);
  EXPECT_LT(hidden, c.points.size());
  // The far side's inner rim (y > 0.4, on the hole's side of the far tube) is partly hidden.
  size_t hiddenFarRim = 0;
  for (size_t i = 0; i < c.points.size(); ++i) {
    const Vec3& p = c.points[i].position;
    hiddenFarRim += !c.visible[i] && p.y > 0.4 && std::hypot(p.x, p.y) < 1.0;
  }
  EXPECT_GT(hiddenFarRim, 5u);
  // The tube is 0.7 thick: a gap of 0.1 separates occluders from the point's own sheet.
  auto [covered, exposed] =
      expectAgreesWithReferenceDepth(testing::torus(24, 12, false), view, c, 0.1);
  EXPECT_GT(covered, 5u);
  EXPECT_GT(exposed, 100u);
  Contours naive =
      contours(testing::torus(24, 12, false), view, silhouette::CurveMode::Exact, 5, 0);
  std::printf(
      "torus nearly edge-on: %zu polylines, %zu points, %zu hidden (%zu on the far "
      "inner rim; naive ray: %zu); reference depth: %zu covered, %zu exposed\n",
      c.lines.size(), c.points.size(), hidden, hiddenFarRim, countHidden(naive.visible), covered,
      exposed);
}

}  // namespace
}  // namespace limn::render::oracle
