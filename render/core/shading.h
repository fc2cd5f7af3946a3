// The one shading model of limn: a headlight at the eye, Blinn-Phong. The rasteriser's fragment
// shader and the reference's ray caster both take their constants from here, so images of the
// same surface agree wherever the normals agree.
#pragma once

#include <algorithm>
#include <cmath>

#include "render/core/vec.h"

namespace limn::render::shading {

inline constexpr float kBackground[3] = {0.12f, 0.12f, 0.14f};
inline constexpr float kFrontAlbedo[3] = {0.80f, 0.62f, 0.38f};
inline constexpr float kBackAlbedo[3] = {0.40f, 0.55f, 0.80f};  // inside of open surfaces
inline constexpr float kAmbient = 0.12f;
inline constexpr float kDiffuse = 0.78f;
inline constexpr float kSpecular = 0.25f;
inline constexpr float kShininess = 40.0f;
inline constexpr float kWireColor[3] = {0.05f, 0.05f, 0.05f};

// Shades a surface point with unit normal n seen along unit direction toEye (from the point to
// the eye). With a headlight the half vector equals toEye. Back faces (n facing away) get the
// back albedo and the flipped normal. Writes linear RGB in [0, 1].
inline void shade(const Vec3& n, const Vec3& toEye, float rgb[3]) {
  double ndotv = dot(n, toEye);
  const float* albedo = ndotv >= 0 ? kFrontAlbedo : kBackAlbedo;
  double c = std::fabs(ndotv);
  double spec = std::pow(c, static_cast<double>(kShininess));
  for (int i = 0; i < 3; ++i) {
    double value = albedo[i] * (kAmbient + kDiffuse * c) + kSpecular * spec;
    rgb[i] = static_cast<float>(std::clamp(value, 0.0, 1.0));
  }
}

}  // namespace limn::render::shading
