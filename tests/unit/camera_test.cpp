// resolveCamera with an orbit: the eye at its angles and distance (in bounding-sphere radii)
// from the target, the default framing when no distance is given, and an up vector that keeps
// the view upright at any elevation.
#include "render/core/camera.h"

#include <gtest/gtest.h>

#include <cmath>

namespace limn::render {
namespace {

void expectNear(const Vec3& a, const Vec3& b, double tolerance = 1e-12) {
  EXPECT_NEAR(a.x, b.x, tolerance);
  EXPECT_NEAR(a.y, b.y, tolerance);
  EXPECT_NEAR(a.z, b.z, tolerance);
}

const Bounds kBox = [] {
  Bounds b;
  b.extend({-1, -2, -3});
  b.extend({3, 2, 1});  // centre (1, 0, -1), radius sqrt(12)
  return b;
}();

TEST(OrbitCamera, AzimuthAndElevationPlaceTheEyeAroundTheCentre) {
  const double r = std::sqrt(12.0);
  CameraSpec spec;
  spec.orbit = Orbit{90, 0, 2.0};
  Camera side = resolveCamera(spec, kBox);
  expectNear(side.eye(), Vec3{1 + 2 * r, 0, -1});
  expectNear(side.target(), Vec3{1, 0, -1});
  expectNear(side.up(), Vec3{0, 1, 0});

  spec.orbit = Orbit{0, 90, 3.0};
  Camera above = resolveCamera(spec, kBox);
  expectNear(above.eye(), Vec3{1, 3 * r, -1});
  // Straight down, "up" on the picture is -Z (the direction the eye came from when rising).
  expectNear(above.up(), Vec3{0, 0, -1});
  EXPECT_NEAR(dot(above.trueUp(), Vec3{0, 0, -1}), 1.0, 1e-12);
}

TEST(OrbitCamera, WithoutADistanceFramesLikeTheDefaultCamera) {
  CameraSpec plain;
  CameraSpec orbit;
  orbit.orbit = Orbit{};
  expectNear(resolveCamera(orbit, kBox).eye(), resolveCamera(plain, kBox).eye());
  orbit.orbit = Orbit{-45, 30, std::nullopt};
  Camera turned = resolveCamera(orbit, kBox);
  EXPECT_NEAR(length(turned.eye() - Vec3{1, 0, -1}),
              length(resolveCamera(plain, kBox).eye() - Vec3{1, 0, -1}), 1e-9);
  EXPECT_LT(turned.eye().x, 1.0);  // negative azimuth: towards -X
  EXPECT_GT(turned.eye().y, 0.0);
}

TEST(OrbitCamera, KeepsAGivenTargetAndUp) {
  CameraSpec spec;
  spec.orbit = Orbit{180, 0, 1.5};
  spec.target = Vec3{0, 0, 0};
  spec.up = Vec3{1, 0, 0};
  Camera camera = resolveCamera(spec, kBox);
  expectNear(camera.eye(), Vec3{0, 0, -1.5 * std::sqrt(12.0)}, 1e-9);
  expectNear(camera.up(), Vec3{1, 0, 0});
}

}  // namespace
}  // namespace limn::render
