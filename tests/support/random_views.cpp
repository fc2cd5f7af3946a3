#include "tests/support/random_views.h"

#include <cmath>
#include <cstdio>
#include <random>

namespace limn::testing {

using render::Vec3;

namespace {

// A double in [0, 1) from the generator's raw bits: std::uniform_real_distribution is not
// specified bit for bit, and a view must be the same on every standard library.
double unit(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

Vec3 onUnitSphere(std::mt19937_64& rng) {
  double z = 2 * unit(rng) - 1, a = 2 * M_PI * unit(rng);
  double r = std::sqrt(std::max(0.0, 1 - z * z));
  return {r * std::cos(a), r * std::sin(a), z};
}

std::string number(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.17g", x);
  return text;
}

std::string vector(const Vec3& v) {
  return "[" + number(v.x) + ", " + number(v.y) + ", " + number(v.z) + "]";
}

}  // namespace

uint64_t viewSeed(uint64_t seed, const std::string& name) {
  uint64_t hash = 1469598103934665603ull;
  for (unsigned char c : name) hash = (hash ^ c) * 1099511628211ull;
  return hash ^ seed;
}

std::vector<RandomView> randomViews(const render::Bounds& bounds, int count, uint64_t seed,
                                    int side) {
  std::vector<RandomView> views;
  const double radius = std::max(bounds.diagonal() / 2, 1e-12);
  for (int i = 0; i < count; ++i) {
    std::mt19937_64 rng(seed * 1000003u + static_cast<uint64_t>(i));
    const Vec3 direction = onUnitSphere(rng);
    const double distance = radius * (1.5 + 2.5 * unit(rng));
    // Up: any direction not within ~8 degrees of the view axis (the camera orthogonalises it).
    Vec3 up = onUnitSphere(rng);
    while (std::fabs(render::dot(up, direction)) > 0.99) up = onUnitSphere(rng);
    const double fov = 20 + 40 * unit(rng);
    const bool ortho = unit(rng) < 0.25;

    render::CameraSpec camera;
    camera.target = bounds.center();
    camera.eye = bounds.center() + direction * distance;
    camera.up = up;
    camera.width = camera.height = side;
    if (ortho) {
      camera.projection = render::Projection::Orthographic;
      camera.orthoHeight = 2 * distance * std::tan(fov * M_PI / 360);
    } else {
      camera.fovYDeg = fov;
    }
    views.push_back({i, camera});
  }
  return views;
}

std::string describeCamera(const render::CameraSpec& camera) {
  std::string out = "{";
  auto add = [&](const std::string& key, const std::string& value) {
    if (out.size() > 1) out += ", ";
    out += "\"" + key + "\": " + value;
  };
  if (camera.eye) add("eye", vector(*camera.eye));
  if (camera.target) add("target", vector(*camera.target));
  if (camera.up) add("up", vector(*camera.up));
  if (camera.fovYDeg) add("fovYDeg", number(*camera.fovYDeg));
  if (camera.projection == render::Projection::Orthographic) {
    add("projection", "\"orthographic\"");
    add("orthoHeight", number(*camera.orthoHeight));
  }
  if (camera.width) add("width", std::to_string(*camera.width));
  if (camera.height) add("height", std::to_string(*camera.height));
  return out + "}";
}

}  // namespace limn::testing
