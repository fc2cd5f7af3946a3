// Implicit fields and polygonisers: falloff formulas, gradients against finite differences,
// Lipschitz bounds, closed meshes from every polygoniser on hand-made and random scenes, vertices
// on the surface, the tracker agreeing with marching cubes, expression checks, cancellation.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "render/core/error.h"
#include "render/implicit/cube_table.h"
#include "render/implicit/field.h"
#include "render/implicit/polygonize.h"

namespace limn::render::implicit {
namespace {

Primitive primitive(PrimitiveType type, Vec3 centre, double radius, double weight = 1,
                    bool negative = false) {
  Primitive p;
  p.type = type;
  p.center = centre;
  p.radius = radius;
  p.weight = weight;
  p.negative = negative;
  return p;
}

FieldSpec single(PrimitiveType type, double radius = 1) {
  return {{primitive(type, {0, 0, 0}, radius)}, 0.5};
}

// A random scene: up to 8 primitives of the blob kinds, scaled and rotated, some negative.
FieldSpec randomScene(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1), r(0.5, 1.2), w(0.7, 1.5), s(0.6, 1.6),
      angle(0, 180);
  FieldSpec spec;
  spec.iso = 0.5;
  const int count = 3 + static_cast<int>(rng() % 6);
  for (int i = 0; i < count; ++i) {
    const PrimitiveType types[] = {PrimitiveType::Blobby, PrimitiveType::Metaball,
                                   PrimitiveType::Soft};
    Primitive p = primitive(types[rng() % 3], {u(rng), u(rng), u(rng)}, r(rng), w(rng),
                            i > 0 && rng() % 4 == 0);
    p.transform.scale = {s(rng), s(rng), s(rng)};
    p.transform.rotateDeg = {angle(rng), angle(rng), angle(rng)};
    spec.primitives.push_back(p);
  }
  return spec;
}

TEST(ImplicitField, FalloffsHaveTheirPublishedValues) {
  {
    Field f(single(PrimitiveType::Soft, 2.0));
    FieldEvaluator e(f);
    EXPECT_NEAR(e.value({0, 0, 0}) + 0.5, 1.0, 1e-12);
    EXPECT_NEAR(e.value({1.0, 0, 0}) + 0.5, 0.5, 1e-12);  // Wyvill: half the weight at b / 2
    EXPECT_NEAR(e.value({2.0, 0, 0}) + 0.5, 0.0, 1e-12);
  }
  {
    Field f(single(PrimitiveType::Metaball, 3.0));
    FieldEvaluator e(f);
    EXPECT_NEAR(e.value({1.0, 0, 0}) + 0.5, 1.0 - 3.0 / 9.0, 1e-12);              // r = b / 3
    EXPECT_NEAR(e.value({0, 2.0, 0}) + 0.5, 1.5 * (1.0 / 3) * (1.0 / 3), 1e-12);  // r = 2b / 3
    EXPECT_NEAR(e.value({0, 0, 3.5}) + 0.5, 0.0, 1e-12);
  }
  {
    Primitive p = primitive(PrimitiveType::Blobby, {0, 0, 0}, 1.0, 2.0);
    p.blobbiness = 3;
    Field f({{p}, 0.5});
    FieldEvaluator e(f);
    EXPECT_NEAR(e.value({0.5, 0, 0}) + 0.5, 2.0 * std::exp(-3.0 * 0.25), 1e-12);
  }
}

TEST(ImplicitField, GradientsMatchFiniteDifferences) {
  std::vector<Primitive> all;
  for (PrimitiveType type : {PrimitiveType::Blobby, PrimitiveType::Metaball, PrimitiveType::Soft,
                             PrimitiveType::Torus, PrimitiveType::Cube}) {
    Primitive p = primitive(type, {0.1, -0.2, 0.3}, 1.3);
    p.majorRadius = 0.8;
    p.transform.scale = {1.2, 0.7, 1.1};
    p.transform.rotateDeg = {20, 35, -50};
    p.transform.translate = {0.2, 0.1, 0};
    all.push_back(p);
  }
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.2, 1.2);
  for (const Primitive& p : all) {
    Field f({{p}, 0.3});
    FieldEvaluator e(f);
    for (int n = 0; n < 200; ++n) {
      const Vec3 x{u(rng), u(rng), u(rng)};
      Vec3 g;
      e.valueAndGradient(x, g);
      const double h = 1e-6;
      const Vec3 fd{(e.value(x + Vec3{h, 0, 0}) - e.value(x - Vec3{h, 0, 0})) / (2 * h),
                    (e.value(x + Vec3{0, h, 0}) - e.value(x - Vec3{0, h, 0})) / (2 * h),
                    (e.value(x + Vec3{0, 0, h}) - e.value(x - Vec3{0, 0, h})) / (2 * h)};
      EXPECT_NEAR(length(g - fd), 0.0, 1e-5 * (1 + length(g)))
          << primitiveTypeName(p.type) << " at " << x.x << " " << x.y << " " << x.z;
    }
  }
}

TEST(ImplicitField, LipschitzBoundHolds) {
  for (unsigned seed = 1; seed <= 10; ++seed) {
    Field f(randomScene(seed));
    FieldEvaluator e(f);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-2.5, 2.5), d(-0.05, 0.05);
    for (int n = 0; n < 2000; ++n) {
      const Vec3 p{u(rng), u(rng), u(rng)}, q = p + Vec3{d(rng), d(rng), d(rng)};
      const double bound = e.lipschitzNear(p, 0.1) * length(q - p);
      EXPECT_LE(std::fabs(e.value(p) - e.value(q)), bound * 1.0001 + 1e-12) << seed;
    }
  }
}

TEST(ImplicitField, ExpressionsMayOnlyUseXyz) {
  for (const char* bad : {"x + w", "foo(x)", "x +* 2", "", "system(1)", "\"a\""}) {
    Primitive p = primitive(PrimitiveType::Expression, {0, 0, 0}, 1);
    p.expression = bad;
    p.negative = true;
    FieldSpec spec{{primitive(PrimitiveType::Soft, {0, 0, 0}, 1), p}, 0.5};
    EXPECT_THROW(Field{spec}, InputError) << bad;
  }
  Primitive cut = primitive(PrimitiveType::Expression, {0, 0, 0}, 1, 400.0, true);
  cut.expression = "x^2 + y^2 - 0.04";
  Field f({{primitive(PrimitiveType::Soft, {0, 0, 0}, 2), cut}, 0.5});
  FieldEvaluator e(f);
  EXPECT_LT(e.value({0, 0, 0}), 0.0);  // the hole along z
  EXPECT_GT(e.value({0.5, 0, 0}), 0.0);
}

TEST(CubeTable, EveryConfigurationIsSymmetricUnderComplementCount) {
  const CubeTable& table = CubeTable::instance();
  EXPECT_TRUE(table.triangles(0).empty());
  EXPECT_TRUE(table.triangles(255).empty());
  EXPECT_EQ(table.triangles(1).size(), 3u);
  for (int c = 1; c < 255; ++c) EXPECT_FALSE(table.triangles(c).empty()) << c;
}

struct Polygonised {
  Polygonization result;
  MeshClosure closure;
};

Polygonised run(const FieldSpec& spec, PolygonizerMethod method, int resolution,
                double flatness = 0.9) {
  Field field(spec);
  PolygonizerOptions options;
  options.method = method;
  options.resolution = resolution;
  options.flatness = flatness;
  Polygonised out{polygonize(field, options, CancelToken{}), {}};
  out.closure = checkClosure(out.result.mesh);
  return out;
}

TEST(Polygonize, SphereIsClosedAndOnTheSurface) {
  // One soft object of radius 2 at iso 0.5: the sphere of radius 1, exactly.
  for (PolygonizerMethod method : {PolygonizerMethod::MarchingCubes, PolygonizerMethod::Tracker,
                                   PolygonizerMethod::Octree, PolygonizerMethod::Adaptive}) {
    Polygonised p = run(single(PrimitiveType::Soft, 2.0), method, 40);
    const auto& mesh = p.result.mesh;
    ASSERT_GT(mesh.triangleCount(), 100u) << polygonizerName(method);
    EXPECT_TRUE(p.closure.closed())
        << polygonizerName(method) << " boundary " << p.closure.boundaryEdges << " non-manifold "
        << p.closure.nonManifoldEdges;
    EXPECT_EQ(p.closure.misorientedEdges, 0u) << polygonizerName(method);
    for (size_t v = 0; v < mesh.vertexCount(); ++v) {
      const Vec3 x = mesh.positions[v].toDouble();
      ASSERT_NEAR(length(x), 1.0, 1e-3) << polygonizerName(method);
      // Normals point outwards and the triangles wind counter-clockwise seen from outside.
      ASSERT_GT(dot(mesh.normals[v].toDouble(), x), 0.99);
    }
    double signedVolume = 0;
    for (size_t t = 0; t < mesh.indices.size(); t += 3) {
      const Vec3 a = mesh.positions[mesh.indices[t]].toDouble(),
                 b = mesh.positions[mesh.indices[t + 1]].toDouble(),
                 c = mesh.positions[mesh.indices[t + 2]].toDouble();
      signedVolume += dot(a, cross(b, c)) / 6.0;
    }
    // The octree and adaptive meshes keep flat-enough (25 degrees at the default flatness 0.9)
    // regions coarse: their chords cut more volume off.
    const bool coarse =
        method == PolygonizerMethod::Octree || method == PolygonizerMethod::Adaptive;
    EXPECT_NEAR(signedVolume, 4.0 / 3.0 * M_PI, coarse ? 0.2 : 0.03) << polygonizerName(method);
  }
}

TEST(Polygonize, StricterFlatnessRefinesTowardsTheSurface) {
  for (PolygonizerMethod method : {PolygonizerMethod::Octree, PolygonizerMethod::Adaptive}) {
    Polygonised loose = run(single(PrimitiveType::Soft, 2.0), method, 40, 0.9);
    Polygonised strict = run(single(PrimitiveType::Soft, 2.0), method, 40, 0.995);
    EXPECT_GT(strict.result.mesh.triangleCount(), loose.result.mesh.triangleCount());
    EXPECT_TRUE(strict.closure.closed()) << polygonizerName(method);
    Field field(single(PrimitiveType::Soft, 2.0));
    const double looseError =
        measureImplicitGeometry(loose.result.mesh, field, CancelToken{}).relMaxDist;
    const double strictError =
        measureImplicitGeometry(strict.result.mesh, field, CancelToken{}).relMaxDist;
    EXPECT_LT(strictError, looseError * 0.5) << polygonizerName(method);
  }
}

TEST(Polygonize, RandomScenesAreClosedByEveryMethod) {
  for (unsigned seed = 1; seed <= 12; ++seed) {
    const FieldSpec spec = randomScene(seed);
    Polygonised mc = run(spec, PolygonizerMethod::MarchingCubes, 48);
    EXPECT_TRUE(mc.closure.closed()) << "marching cubes, seed " << seed;
    EXPECT_EQ(mc.closure.misorientedEdges, 0u) << seed;
    for (PolygonizerMethod method :
         {PolygonizerMethod::Tracker, PolygonizerMethod::Octree, PolygonizerMethod::Adaptive}) {
      Polygonised p = run(spec, method, 48);
      EXPECT_TRUE(p.closure.closed())
          << polygonizerName(method) << " seed " << seed << ": boundary " << p.closure.boundaryEdges
          << ", non-manifold " << p.closure.nonManifoldEdges;
      EXPECT_EQ(p.closure.misorientedEdges, 0u) << polygonizerName(method) << " seed " << seed;
    }
  }
}

TEST(Polygonize, TrackerDrawsTheSameTrianglesAsMarchingCubes) {
  for (unsigned seed = 1; seed <= 12; ++seed) {
    const FieldSpec spec = randomScene(seed);
    Polygonised mc = run(spec, PolygonizerMethod::MarchingCubes, 40);
    Polygonised tracked = run(spec, PolygonizerMethod::Tracker, 40);
    EXPECT_EQ(tracked.result.mesh.triangleCount(), mc.result.mesh.triangleCount()) << seed;
    EXPECT_LT(tracked.result.stats.cellsVisited, mc.result.stats.cellsVisited / 2) << seed;
  }
}

TEST(Polygonize, GeometricErrorShrinksWithResolution) {
  const FieldSpec spec = randomScene(3);
  Field field(spec);
  double previous = 1e300;
  for (int resolution : {20, 40, 80}) {
    PolygonizerOptions options;
    options.resolution = resolution;
    Polygonization p = polygonize(field, options, CancelToken{});
    ImplicitGeometryError error = measureImplicitGeometry(p.mesh, field, CancelToken{});
    EXPECT_LT(error.relMeanDist, previous);
    previous = error.relMeanDist;
  }
  EXPECT_LT(previous, 2e-4);
}

TEST(Polygonize, HonoursCancellationAndTheTriangleLimit) {
  Field field(randomScene(5));
  PolygonizerOptions options;
  options.resolution = 200;
  CancelToken cancelled;
  cancelled.cancel();
  EXPECT_THROW(polygonize(field, options, cancelled), Cancelled);
  options.maxTriangles = 1000;
  EXPECT_THROW(polygonize(field, options, CancelToken{}), InputError);
}

}  // namespace
}  // namespace limn::render::implicit
