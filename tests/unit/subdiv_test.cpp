// LimitSurface against values known in closed form.
#include "render/subdiv/limit_surface.h"

#include <gtest/gtest.h>

#include <cmath>
#include <atomic>
#include <numbers>
#include <set>
#include <thread>

#include "render/core/error.h"
#include "tests/unit/test_meshes.h"

namespace limn::render::subdiv {
namespace {

double bsplineBasis(int k, double t) {
  switch (k) {
    case 0: return (1 - t) * (1 - t) * (1 - t) / 6;
    case 1: return (3 * t * t * t - 6 * t * t + 4) / 6;
    case 2: return (-3 * t * t * t + 3 * t * t + 3 * t + 1) / 6;
    default: return t * t * t / 6;
  }
}

TEST(LimitSurface, RegularCatmullClarkFaceIsTheBicubicBSpline) {
  const int n = 5;
  mesh::ControlMesh m = testing::grid(n, 0.3);
  LimitSurface surface(m);
  // Face (2, 2) of the 5x5 grid is regular: its 4x4 neighbourhood is interior.
  const int face = 2 * n + 2;
  for (double u : {0.0, 0.25, 0.5, 0.9, 1.0}) {
    for (double v : {0.0, 0.3, 0.75, 1.0}) {
      Vec3 expected{0, 0, 0};
      for (int a = 0; a < 4; ++a) {
        for (int b = 0; b < 4; ++b) {
          int i = 2 - 1 + a, j = 2 - 1 + b;
          expected += m.points[j * (n + 1) + i] * (bsplineBasis(a, u) * bsplineBasis(b, v));
        }
      }
      Vec3 got = surface.position(face, u, v);
      EXPECT_NEAR(length(got - expected), 0.0, 1e-12) << "u=" << u << " v=" << v;
    }
  }
}

TEST(LimitSurface, LoopVertexLimitMatchesTheLimitMask) {
  mesh::ControlMesh m = testing::icosahedron();
  LimitSurface surface(m);
  // Every icosahedron vertex has valence 5; Loop's beta and limit weight chi = 1/(3/(8 beta)+n).
  const int n = 5;
  double c = 3.0 / 8.0 + 0.25 * std::cos(2 * std::numbers::pi / n);
  double beta = (5.0 / 8.0 - c * c) / n;
  double chi = 1.0 / (3.0 / (8.0 * beta) + n);
  for (int vertex = 0; vertex < m.vertexCount(); ++vertex) {
    // Neighbours: the other vertices of faces around `vertex`.
    std::set<int> ring;
    for (int f = 0; f < m.faceCount(); ++f) {
      const int* fv = &m.faceVertexIndices[3 * f];
      if (fv[0] == vertex || fv[1] == vertex || fv[2] == vertex) {
        for (int k = 0; k < 3; ++k) if (fv[k] != vertex) ring.insert(fv[k]);
      }
    }
    ASSERT_EQ(static_cast<int>(ring.size()), n);
    Vec3 expected = m.points[vertex] * (1 - n * chi);
    for (int q : ring) expected += m.points[q] * chi;
    EXPECT_NEAR(length(surface.controlLimitPositions()[vertex] - expected), 0.0, 1e-9);
    // By symmetry the limit normal points away from the centre.
    EXPECT_GT(dot(surface.controlLimitNormals()[vertex], normalize(m.points[vertex])), 0.9999);
  }
}

TEST(LimitSurface, CubeIsSymmetricAndNormalsPointOutwards) {
  LimitSurface surface(testing::cube());
  double r0 = length(surface.controlLimitPositions()[0]);
  for (int v = 0; v < 8; ++v) {
    EXPECT_NEAR(length(surface.controlLimitPositions()[v]), r0, 1e-12);
  }
  for (int f = 0; f < surface.faceCount(); ++f) {
    Vec2 c = surface.centerUV(f);
    LimitSample s = surface.evaluate(f, c.x, c.y);
    EXPECT_GT(dot(s.normal, normalize(s.position)), 0.9999) << "face " << f;
  }
}

TEST(LimitSurface, InfinitelySharpCreaseStaysOnTheCreaseEdge) {
  mesh::ControlMesh m = testing::cube();
  for (auto [a, b] : {std::pair{0, 1}, {1, 3}, {3, 2}, {2, 0}}) {
    m.creases.push_back({a, b, mesh::kInfiniteSharpness});
  }
  LimitSurface surface(m);
  // The front face's boundary is an infinitely sharp crease loop: its limit is the uniform
  // cubic B-spline of the four corners, which lies in their plane z = 0.5.
  for (double u : {0.0, 0.3, 0.5, 1.0}) {
    EXPECT_NEAR(surface.position(0, u, 0.0).z, 0.5, 1e-12);
  }
}

TEST(LimitSurface, HolesHaveNoLimitSurface) {
  mesh::ControlMesh m = testing::cube();
  m.holes = {2};
  LimitSurface surface(m);
  EXPECT_FALSE(surface.hasLimit(2));
  EXPECT_TRUE(surface.hasLimit(0));
}

TEST(LimitSurface, EvaluationIsThreadSafe) {
  LimitSurface surface(testing::torus());
  Vec3 expected = surface.position(5, 0.3, 0.7);
  std::vector<std::thread> threads;
  std::atomic<int> mismatches{0};
  for (int t = 0; t < 4; ++t) {
    threads.emplace_back([&] {
      for (int i = 0; i < 2000; ++i) {
        if (length(surface.position(5, 0.3, 0.7) - expected) != 0) ++mismatches;
        surface.evaluate(i % surface.faceCount(), 0.5, 0.5);
      }
    });
  }
  for (auto& th : threads) th.join();
  EXPECT_EQ(mismatches.load(), 0);
}

}  // namespace
}  // namespace limn::render::subdiv

namespace limn::render::subdiv {
namespace {

TEST(LimitSurface, RefusesInteriorValenceTwoVertices) {
  // A closed "pillow" of three quads: vertices 0, 2 and 4 are interior with valence 2.
  mesh::ControlMesh m;
  m.points = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}, {0, 0, 0.2}};
  testing::addFace(m, {0, 1, 4, 3});
  testing::addFace(m, {1, 2, 3, 4});
  testing::addFace(m, {0, 3, 2, 1});
  try {
    LimitSurface surface(m);
    FAIL() << "expected a refusal";
  } catch (const InputError& e) {
    EXPECT_EQ(e.kind(), InputError::Kind::InvalidMesh);
    EXPECT_EQ(e.subject(), "vertex 0");
    EXPECT_NE(std::string(e.what()).find("valence 2"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace limn::render::subdiv
