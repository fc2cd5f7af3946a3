// Coarse, uniform and adaptive tessellation: counts, watertightness, points on the surface.
#include "render/tessellate/tessellate.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <tuple>

#include "render/core/error.h"
#include "render/core/parallel.h"
#include "render/tessellate/contour_proximity.h"
#include "tests/unit/test_meshes.h"

namespace limn::render::tessellate {
namespace {

using Key = std::tuple<float, float, float>;
Key keyOf(const Vec3f& p) { return {p.x, p.y, p.z}; }

// Counts, for every undirected edge (vertices identified by exact position), how many
// triangles use it.
std::map<std::pair<Key, Key>, int> edgeUse(const TriangleMesh& mesh) {
  std::map<std::pair<Key, Key>, int> use;
  for (size_t t = 0; t < mesh.indices.size(); t += 3) {
    for (int c = 0; c < 3; ++c) {
      Key a = keyOf(mesh.positions[mesh.indices[t + c]]);
      Key b = keyOf(mesh.positions[mesh.indices[t + (c + 1) % 3]]);
      ++use[{std::min(a, b), std::max(a, b)}];
    }
  }
  return use;
}

Camera frontCamera(const subdiv::LimitSurface& surface, int size) {
  CameraSpec spec;
  spec.width = size;
  spec.height = size;
  spec.eye = Vec3{1.2, 1.6, 3.0};
  return resolveCamera(spec, surface.bounds());
}

TEST(Coarse, FansPolygonsAndSkipsHoles) {
  mesh::ControlMesh m = testing::cube();
  m.holes = {1};
  subdiv::LimitSurface surface(m);
  TriangleMesh mesh = tessellateCoarse(surface);
  EXPECT_EQ(mesh.triangleCount(), 10u);
  EXPECT_EQ(mesh.limitPositions.size(), 8u);
  EXPECT_EQ(mesh.lines.size() / 2, 12u);  // every cube edge once, as polygon edges
}

TEST(Uniform, CountsAndLimitPositions) {
  subdiv::LimitSurface surface(testing::cube());
  for (int level : {1, 2, 3}) {
    TriangleMesh mesh = tessellateUniform(surface, level, 1'000'000);
    size_t quads = 24u << (2 * (level - 1));
    EXPECT_EQ(mesh.triangleCount(), 2 * quads) << "level " << level;
    ASSERT_EQ(mesh.limitPositions.size(), mesh.positions.size());
  }
  // The refined vertices converge to their limit positions as the level grows.
  auto maxGap = [&](int level) {
    TriangleMesh mesh = tessellateUniform(surface, level, 1'000'000);
    double gap = 0;
    for (size_t v = 0; v < mesh.positions.size(); ++v) {
      gap = std::max(gap, length(mesh.positions[v].toDouble() - mesh.limitPositions[v].toDouble()));
    }
    return gap;
  };
  EXPECT_LT(maxGap(3), maxGap(1) / 8);
}

TEST(Uniform, RefusesMoreTrianglesThanTheLimit) {
  subdiv::LimitSurface surface(testing::cube());
  try {
    tessellateUniform(surface, 6, 10'000);
    FAIL() << "expected LimitExceeded";
  } catch (const InputError& e) {
    EXPECT_EQ(e.kind(), InputError::Kind::LimitExceeded);
    EXPECT_EQ(e.subject(), "maxTriangles");
  }
}

TEST(Uniform, LoopMeshesStayTriangles) {
  subdiv::LimitSurface surface(testing::icosahedron());
  EXPECT_EQ(tessellateUniform(surface, 2, 1'000'000).triangleCount(), 20u * 16u);
}

// limn's own rules draw the same mesh as OpenSubdiv: same vertices in the same order, same
// limit positions, normals within float precision (render/rules is tested shape by shape in
// rules_test.cpp; this checks the assembly).
TEST(Uniform, OwnRulesDrawWhatOpenSubdivDraws) {
  for (const mesh::ControlMesh& cage :
       {testing::cube(), testing::torus(), testing::icosahedron()}) {
    subdiv::LimitSurface surface(cage);
    UniformOptions options;
    options.level = 2;
    options.engine = UniformEngine::OpenSubdiv;
    TriangleMesh far = tessellateUniform(surface, options);
    // Level 0 is the cage for every engine (only the normals come from different evaluators).
    options.engine = UniformEngine::Masks;
    options.level = 0;
    EXPECT_EQ(tessellateUniform(surface, options).indices, tessellateCoarse(surface).indices);
    options.level = 2;
    for (UniformEngine engine : {UniformEngine::Masks, UniformEngine::Factored}) {
      if (engine == UniformEngine::Factored &&
          (cage.scheme == mesh::Scheme::Loop || !cage.creases.empty())) {
        continue;
      }
      options.engine = engine;
      TriangleMesh own = tessellateUniform(surface, options);
      ASSERT_EQ(own.indices, far.indices);
      ASSERT_EQ(own.lines, far.lines);
      ASSERT_EQ(own.positions.size(), far.positions.size());
      for (size_t v = 0; v < far.positions.size(); ++v) {
        EXPECT_LT(length(own.positions[v].toDouble() - far.positions[v].toDouble()), 1e-6);
        EXPECT_LT(length(own.limitPositions[v].toDouble() - far.limitPositions[v].toDouble()),
                  1e-6);
        const Vec3 a = own.normals[v].toDouble(), b = far.normals[v].toDouble();
        EXPECT_LT(std::atan2(length(cross(a, b)), dot(a, b)) * 180 / M_PI, 0.01) << "vertex " << v;
      }
    }
  }
}

bool sameMesh(const TriangleMesh& a, const TriangleMesh& b) {
  const auto same = [](const std::vector<Vec3f>& x, const std::vector<Vec3f>& y) {
    return x.size() == y.size() && std::equal(x.begin(), x.end(), y.begin(), [](auto p, auto q) {
             return p.x == q.x && p.y == q.y && p.z == q.z;
           });
  };
  return same(a.positions, b.positions) && same(a.normals, b.normals) &&
         same(a.limitPositions, b.limitPositions) && a.indices == b.indices && a.lines == b.lines;
}

// The refinement's loops write every element from one task: one thread and two draw the same
// mesh bit for bit (quads and Loop's triangles on halfedges with holes, a boundary, creases,
// after their first levels on the Topology path).
TEST(Uniform, OneThreadAndTwoDrawTheSameMesh) {
  mesh::ControlMesh creature = testing::creature(10);
  creature.holes = {3, 40, 41};
  mesh::ControlMesh loopCreature = testing::loopCreature(8);
  loopCreature.holes = {5, 70, 71};
  for (const mesh::ControlMesh& cage : {creature, loopCreature, testing::icosahedron()}) {
    subdiv::LimitSurface surface(cage);
    for (UniformEngine engine : {UniformEngine::Auto, UniformEngine::Masks}) {
      UniformOptions options;
      options.level = 3;
      options.engine = engine;
      parallelThreadLimit() = 1;
      TriangleMesh one = tessellateUniform(surface, options);
      parallelThreadLimit() = 2;
      TriangleMesh two = tessellateUniform(surface, options);
      parallelThreadLimit() = 0;
      EXPECT_GT(one.triangleCount(), 0u);
      EXPECT_TRUE(sameMesh(one, two)) << mesh::schemeName(cage.scheme);
    }
  }
}

TriangleMesh drawnBy(const mesh::ControlMesh& cage, UniformEngine engine, int level = 2) {
  subdiv::LimitSurface surface(cage);
  UniformOptions options;
  options.level = level;
  options.engine = engine;
  return tessellateUniform(surface, options);
}

// "auto" takes limn's masks where they take the mesh (Catmull-Clark and Loop) and OpenSubdiv
// elsewhere: a non-manifold mesh (three quads on one edge) is drawn, as OpenSubdiv draws it,
// not refused.
TEST(Uniform, AutoFallsBackToOpenSubdivWhereTheRulesCannot) {
  mesh::ControlMesh fin;
  fin.points = {{0, 0, 0},    {1, 0, 0},    {0, 1, 0},   {1, 1, 0},
                {0, -1, 0.2}, {1, -1, 0.2}, {0, 0.2, 1}, {1, 0.2, 1}};
  testing::addFace(fin, {0, 1, 3, 2});
  testing::addFace(fin, {1, 0, 4, 5});
  testing::addFace(fin, {0, 1, 7, 6});
  EXPECT_TRUE(sameMesh(drawnBy(fin, UniformEngine::Auto), drawnBy(fin, UniformEngine::OpenSubdiv)));
  mesh::ControlMesh bilinear = testing::cube();
  bilinear.scheme = mesh::Scheme::Bilinear;
  EXPECT_TRUE(sameMesh(drawnBy(bilinear, UniformEngine::Auto),
                       drawnBy(bilinear, UniformEngine::OpenSubdiv)));
  // A vertex in no face stays where it is, without a normal, in both engines.
  mesh::ControlMesh loose = testing::cube();
  loose.points.push_back({3, 3, 3});
  const TriangleMesh farLoose = drawnBy(loose, UniformEngine::OpenSubdiv);
  const TriangleMesh autoLoose = drawnBy(loose, UniformEngine::Auto);
  ASSERT_EQ(autoLoose.positions.size(), farLoose.positions.size());
  EXPECT_EQ(length(autoLoose.positions[8].toDouble() - Vec3{3, 3, 3}), 0.0);
  EXPECT_EQ(autoLoose.indices, farLoose.indices);

  for (const mesh::ControlMesh& cage : {testing::torus(), testing::loopCreature(6)}) {
    EXPECT_TRUE(sameMesh(drawnBy(cage, UniformEngine::Auto), drawnBy(cage, UniformEngine::Masks)));
  }
}

TEST(Uniform, PushToLimitMovesEveryVertexToItsLimit) {
  subdiv::LimitSurface surface(testing::torus());
  for (UniformEngine engine : {UniformEngine::OpenSubdiv, UniformEngine::Masks}) {
    for (int level : {0, 2}) {
      UniformOptions options;
      options.level = level;
      options.engine = engine;
      TriangleMesh refined = tessellateUniform(surface, options);
      options.pushToLimit = true;
      TriangleMesh pushed = tessellateUniform(surface, options);
      double before = 0;
      for (size_t v = 0; v < pushed.positions.size(); ++v) {
        EXPECT_EQ(length(pushed.positions[v].toDouble() - pushed.limitPositions[v].toDouble()),
                  0.0);
        before = std::max(
            before, length(refined.positions[v].toDouble() - refined.limitPositions[v].toDouble()));
      }
      EXPECT_GT(before, 1e-3) << "the refined vertices were already on the limit";
    }
  }
}

TEST(Uniform, FactoredRefusesLoop) {
  subdiv::LimitSurface surface(testing::icosahedron());
  UniformOptions options;
  options.engine = UniformEngine::Factored;
  try {
    tessellateUniform(surface, options);
    FAIL() << "factored refined a Loop mesh";
  } catch (const InputError& e) {
    EXPECT_EQ(e.kind(), InputError::Kind::InvalidParameter);
  }
}

class AdaptiveWatertight : public ::testing::TestWithParam<int> {};

TEST_P(AdaptiveWatertight, EveryEdgeHasTwoTriangles) {
  mesh::ControlMesh meshes[] = {testing::cube(), testing::torus(), testing::octahedron(),
                                testing::icosahedron()};
  subdiv::LimitSurface surface(meshes[GetParam()]);
  Camera camera = frontCamera(surface, 256);
  AdaptiveOptions options;
  options.dicingRate = 4.0;
  TriangleMesh mesh = tessellateAdaptive(surface, camera, options, CancelToken());
  ASSERT_GT(mesh.triangleCount(), 100u);
  for (const auto& [edge, count] : edgeUse(mesh)) {
    ASSERT_EQ(count, 2) << "an edge used by " << count << " triangles: the mesh has a crack";
  }
}

INSTANTIATE_TEST_SUITE_P(ClosedMeshes, AdaptiveWatertight, ::testing::Values(0, 1, 2, 3));

TEST(Adaptive, VerticesLieOnTheLimitSurface) {
  subdiv::LimitSurface surface(testing::torus());
  Camera camera = frontCamera(surface, 256);
  TriangleMesh mesh = tessellateAdaptive(surface, camera, AdaptiveOptions{}, CancelToken());
  ASSERT_EQ(mesh.triangleFaces.size(), mesh.triangleCount());
  double worst = 0;
  for (size_t t = 0; t < mesh.triangleCount(); ++t) {
    for (int c = 0; c < 3; ++c) {
      Vec2f uv = mesh.cornerUVs[3 * t + c];
      Vec3 onSurface = surface.position(mesh.triangleFaces[t], uv.x, uv.y);
      worst =
          std::max(worst, length(onSurface - mesh.positions[mesh.indices[3 * t + c]].toDouble()));
    }
  }
  EXPECT_LT(worst, 1e-5);
}

TEST(Adaptive, EdgesAreAboutTheDicingRateOnScreen) {
  subdiv::LimitSurface surface(testing::cube());
  Camera camera = frontCamera(surface, 512);
  for (double rate : {1.0, 4.0}) {
    AdaptiveOptions options;
    options.dicingRate = rate;
    TriangleMesh mesh = tessellateAdaptive(surface, camera, options, CancelToken());
    std::vector<double> lengths;
    for (size_t t = 0; t < mesh.indices.size(); t += 3) {
      Vec3 a = camera.project(mesh.positions[mesh.indices[t]].toDouble());
      Vec3 b = camera.project(mesh.positions[mesh.indices[t + 1]].toDouble());
      lengths.push_back(std::hypot(a.x - b.x, a.y - b.y));
    }
    std::sort(lengths.begin(), lengths.end());
    double median = lengths[lengths.size() / 2];
    EXPECT_GT(median, 0.3 * rate) << "rate " << rate;
    EXPECT_LT(median, 1.5 * rate) << "rate " << rate;
  }
}

TEST(Adaptive, FinerDicingMakesMoreTriangles) {
  subdiv::LimitSurface surface(testing::torus());
  Camera camera = frontCamera(surface, 512);
  AdaptiveOptions coarse, fine;
  coarse.dicingRate = 8;
  fine.dicingRate = 2;
  size_t a = tessellateAdaptive(surface, camera, coarse, CancelToken()).triangleCount();
  size_t b = tessellateAdaptive(surface, camera, fine, CancelToken()).triangleCount();
  EXPECT_GT(b, 8 * a);
}

TEST(Adaptive, SharpCreaseSplitsNormalsButNotPositions) {
  subdiv::LimitSurface surface(testing::torus(12, 8, true));
  Camera camera = frontCamera(surface, 256);
  TriangleMesh mesh = tessellateAdaptive(surface, camera, AdaptiveOptions{}, CancelToken());
  std::map<Key, int> verticesAt;
  for (const Vec3f& p : mesh.positions) ++verticesAt[keyOf(p)];
  int split = 0;
  for (const auto& [key, count] : verticesAt) split += count > 1;
  EXPECT_GT(split, 0) << "the infinitely sharp crease should carry two normals";
}

TEST(Adaptive, RespectsTheTriangleLimit) {
  subdiv::LimitSurface surface(testing::torus());
  Camera camera = frontCamera(surface, 1024);
  AdaptiveOptions options;
  options.dicingRate = 0.5;
  options.maxTriangles = 1000;
  try {
    tessellateAdaptive(surface, camera, options, CancelToken());
    ADD_FAILURE() << "no LimitExceeded";
  } catch (const InputError& e) {
    EXPECT_EQ(e.subject(), "maxTriangles");
    EXPECT_NE(std::string(e.what()).find("adaptive tessellation would make"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("dicingRate"), std::string::npos) << e.what();
  }
  // Another stage's name is the one the message gives.
  options.stage = "reference";
  try {
    tessellateAdaptive(surface, camera, options, CancelToken());
    ADD_FAILURE() << "no LimitExceeded";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("reference tessellation"), std::string::npos) << e.what();
  }
}

TEST(Adaptive, FitToBudgetScalesTheRatesDownInsteadOfRefusing) {
  subdiv::LimitSurface surface(testing::torus());
  Camera camera = frontCamera(surface, 1024);
  AdaptiveOptions options;
  options.dicingRate = 0.5;
  options.maxTriangles = 20000;
  options.fitToBudget = true;
  double scaled = 0;
  options.ratesScaled = &scaled;
  TriangleMesh mesh = tessellateAdaptive(surface, camera, options, CancelToken());
  EXPECT_LE(mesh.triangleCount(), 20000u);
  EXPECT_GT(mesh.triangleCount(), 5000u);
  EXPECT_LT(scaled, 1.0);
  EXPECT_GT(scaled, 0.0);
}

// Owners 0-3: two nearly parallel pieces half a pixel apart (a grazing slit), a piece crossing
// the first at a right angle, and a piece far away.
TEST(ContourProximity, OnlyNearlyParallelPiecesOfDifferentPartsAreNear) {
  const std::vector<ContourPiece> pieces = {{{10, 10}, {30, 10}, 0},
                                            {{10, 10.5}, {30, 11.5}, 1},
                                            {{20, 0}, {20, 20}, 2},
                                            {{10, 50}, {30, 50}, 3}};
  auto none = [](int, int) { return false; };
  EXPECT_EQ(ownersNearAnotherContour(pieces, 4, 1.0, 64, 64, none),
            (std::vector<char>{1, 1, 0, 0}));
  // Neighbours' pieces meet where the contour runs from one to the next: not a slit.
  auto firstTwoAdjacent = [](int a, int b) { return std::min(a, b) == 0 && std::max(a, b) == 1; };
  EXPECT_EQ(ownersNearAnotherContour(pieces, 4, 1.0, 64, 64, firstTwoAdjacent),
            (std::vector<char>{0, 0, 0, 0}));
  // Closer than the distance asked only.
  EXPECT_EQ(ownersNearAnotherContour(pieces, 4, 0.4, 64, 64, none),
            (std::vector<char>{0, 0, 0, 0}));
  // Off the image by more than the distance: not looked at.
  const std::vector<ContourPiece> outside = {{{-40, 10}, {-20, 10}, 0},
                                             {{-40, 10.5}, {-20, 10.5}, 1}};
  EXPECT_EQ(ownersNearAnotherContour(outside, 2, 1.0, 64, 64, none), (std::vector<char>{0, 0}));
  // A face near the eye projects to pieces millions of pixels long: only their part in the
  // image is looked at.
  const std::vector<ContourPiece> huge = {{{-1e12, 10}, {1e12, 10}, 0},
                                          {{-1e12, 10.5}, {1e12, 10.5}, 1}};
  EXPECT_EQ(ownersNearAnotherContour(huge, 2, 1.0, 64, 64, none), (std::vector<char>{1, 1}));
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<ContourPiece> undefined = {{{nan, 10}, {30, 10}, 0},
                                               {{10, 10.5}, {30, 10.5}, 1}};
  EXPECT_EQ(ownersNearAnotherContour(undefined, 2, 1.0, 64, 64, none), (std::vector<char>{0, 0}));
}

TEST(ContourProximity, PiecesJoinWhereTheFacingChangesSign) {
  // A square of points, facing the eye on its left side and away on its right.
  const std::vector<Vec2> square = {{0, 0}, {10, 0}, {10, 10}, {0, 10}};
  std::vector<ContourPiece> pieces;
  appendContourPieces(square, {1, -3, -3, 1}, 7, pieces);
  ASSERT_EQ(pieces.size(), 1u);
  EXPECT_EQ(pieces[0].owner, 7);
  EXPECT_NEAR(pieces[0].a.x, 2.5, 1e-12);  // a quarter of the way from +1 to -3
  EXPECT_NEAR(pieces[0].b.x, 2.5, 1e-12);
  EXPECT_NEAR(std::abs(pieces[0].b.y - pieces[0].a.y), 10, 1e-12);
  pieces.clear();
  appendContourPieces(square, {1, 1, 1, 1}, 7, pieces);
  EXPECT_TRUE(pieces.empty());
}

}  // namespace
}  // namespace limn::render::tessellate
