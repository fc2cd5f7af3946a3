// Analytic displacement (render/subdiv/displacement.h) on the limit surface: the displaced
// point lies at D along the undisplaced normal, the Weingarten derivatives are the displaced
// surface's true derivatives (against central differences of its positions) on Bfr faces,
// Far-patch faces (valence 2) and n-gon sub-faces, for Catmull-Clark and Loop.
#include "render/subdiv/displacement.h"

#include <gtest/gtest.h>

#include <random>

#include "render/subdiv/limit_surface.h"
#include "tests/unit/test_meshes.h"

namespace limn::render::subdiv {
namespace {

using mesh::ControlMesh;

std::vector<std::pair<std::string, ControlMesh>> meshes() {
  using namespace limn::testing;
  return {{"torus", torus(12, 8, false)},
          {"cube", cube()},
          {"pentagonal prism", prism(5)},
          {"valence-2 grid", gridWithValenceTwoVertex()},
          {"loop icosahedron", icosahedron()}};
}

const DisplacementSpec kBumps{DisplacementFunction::Bumps, 0.03, 5};
const DisplacementSpec kRipples{DisplacementFunction::Ripples, -0.02, 3};

// Interior points of each face, seeded.
std::vector<std::pair<int, Vec2>> samplePoints(const LimitSurface& surface, int perFace) {
  std::mt19937 random(11);
  std::uniform_real_distribution<double> unit(0.05, 0.95);
  std::vector<std::pair<int, Vec2>> out;
  for (int f = 0; f < surface.faceCount(); ++f) {
    if (!surface.hasLimit(f)) continue;
    const Vec2 c = surface.centerUV(f);
    for (int k = 0; k < perFace; ++k) {
      // Towards a random corner from the centre: inside every face shape's domain.
      const Vec2 corner = surface.cornerUV(f, k % surface.mesh().faceVertexCounts[f]);
      const double a = unit(random) * 0.9;
      out.push_back({f, Vec2{c.x + (corner.x - c.x) * a, c.y + (corner.y - c.y) * a}});
    }
  }
  return out;
}

TEST(Displacement, DerivativesAreThoseOfTheDisplacedSurface) {
  for (const DisplacementSpec& spec : {kBumps, kRipples}) {
    for (auto& [name, m] : meshes()) {
      const LimitSurface surface(m, CancelToken(), spec);
      ASSERT_TRUE(surface.displaced());
      const double h = 1e-6;
      double worst = 0;
      for (auto [face, uv] : samplePoints(surface, 3)) {
        const LimitSample s = surface.evaluate(face, uv.x, uv.y);
        const Vec3 du =
            (surface.position(face, uv.x + h, uv.y) - surface.position(face, uv.x - h, uv.y)) /
            (2 * h);
        const Vec3 dv =
            (surface.position(face, uv.x, uv.y + h) - surface.position(face, uv.x, uv.y - h)) /
            (2 * h);
        const double scale = std::max(length(s.du), length(s.dv));
        worst = std::max({worst, length(du - s.du) / scale, length(dv - s.dv) / scale});
        // The normal is the displaced surface's: orthogonal to its tangents.
        EXPECT_LT(std::fabs(dot(s.normal, normalize(du))), 1e-5) << name;
      }
      EXPECT_LT(worst, 1e-5) << name << " " << spec.key();
    }
  }
}

TEST(Displacement, MovesEachPointAlongItsNormalByD) {
  for (auto& [name, m] : meshes()) {
    const LimitSurface plain(m, CancelToken());
    const LimitSurface bumpy(m, CancelToken(), kBumps);
    const Displacement d(kBumps, m.bounds());
    double largest = 0;
    for (auto [face, uv] : samplePoints(plain, 2)) {
      const LimitSample s = plain.evaluate(face, uv.x, uv.y);
      const Vec3 f = bumpy.position(face, uv.x, uv.y);
      const double D = d.value(s.position, nullptr);
      EXPECT_LT(length(f - (s.position + s.normal * D)), 1e-12 * m.bounds().diagonal()) << name;
      EXPECT_LE(std::fabs(D), d.reach());
      largest = std::max(largest, std::fabs(D));
    }
    EXPECT_GT(largest, 0.2 * d.reach()) << name << ": the bumps reach the surface";
    // The bounds hold the displaced surface.
    EXPECT_GT(bumpy.bounds().diagonal(), plain.bounds().diagonal());
  }
}

TEST(Displacement, GradientIsTheFunctionsSlope) {
  const Bounds box{{-1, -2, 0}, {3, 1, 2}};
  for (const DisplacementSpec& spec : {kBumps, kRipples}) {
    const Displacement d(spec, box);
    const double h = 1e-6;
    for (Vec3 p : {Vec3{0.3, -0.7, 1.1}, Vec3{2.2, 0.4, 0.1}, Vec3{-0.9, -1.5, 1.9}}) {
      Vec3 gradient;
      d.value(p, &gradient);
      const Vec3 numeric{
          (d.value(p + Vec3{h, 0, 0}, nullptr) - d.value(p - Vec3{h, 0, 0}, nullptr)) / (2 * h),
          (d.value(p + Vec3{0, h, 0}, nullptr) - d.value(p - Vec3{0, h, 0}, nullptr)) / (2 * h),
          (d.value(p + Vec3{0, 0, h}, nullptr) - d.value(p - Vec3{0, 0, h}, nullptr)) / (2 * h)};
      EXPECT_LT(length(gradient - numeric), 1e-6) << spec.key();
    }
  }
}

TEST(Displacement, NoneLeavesTheLimitSurface) {
  const ControlMesh m = limn::testing::torus(12, 8, true);
  const LimitSurface plain(m, CancelToken());
  const LimitSurface none(m, CancelToken(), DisplacementSpec{DisplacementFunction::Bumps, 0, 4});
  EXPECT_FALSE(none.displaced());
  EXPECT_EQ(none.displacementSpec().key(), "");
  for (auto [face, uv] : samplePoints(plain, 1)) {
    const LimitSample a = plain.evaluate(face, uv.x, uv.y), b = none.evaluate(face, uv.x, uv.y);
    EXPECT_EQ(a.position.x, b.position.x);
    EXPECT_EQ(a.normal.y, b.normal.y);
  }
}

}  // namespace
}  // namespace limn::render::subdiv
