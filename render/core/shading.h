// The one shading model of limn: a headlight at the eye, Blinn-Phong, in linear light. The
// rasteriser's fragment shader and the reference's ray caster both take their constants from
// here, so images of the same surface agree wherever the normals agree.
//
// Colours: the constants below (albedos, line colours) and every colour a client gives are sRGB
// display values, as a person picks them; they are made linear where they enter the shading
// (srgbToLinear), light is computed and blended (anti-aliasing, backgrounds) in linear light,
// and the colour passes are written as sRGB by image encoding (render/image/pixel_mapping.h).
// EXR files keep the linear values.
#pragma once

#include <algorithm>
#include <cmath>

#include "render/core/vec.h"

namespace limn::render::shading {

// Under alpha 0 (replaced by the answer's background): values an 8-bit framebuffer holds
// exactly, so that a replaced background is exactly the colour asked for.
inline constexpr float kBackground[3] = {31.0f / 255, 31.0f / 255, 36.0f / 255};
inline constexpr float kFrontAlbedo[3] = {0.80f, 0.62f, 0.38f};
inline constexpr float kBackAlbedo[3] = {0.40f, 0.55f, 0.80f};  // inside of open surfaces
inline constexpr float kAmbient = 0.12f;
inline constexpr float kDiffuse = 0.78f;
inline constexpr float kSpecular = 0.25f;
inline constexpr float kShininess = 40.0f;
inline constexpr float kWireColor[3] = {0.05f, 0.05f, 0.05f};

// The sRGB transfer function (IEC 61966-2-1) and its inverse, on [0, 1].
inline float srgbToLinear(float c) {
  return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}
inline float linearToSrgb(float c) {
  return c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
}

// Shades a surface point with unit normal n seen along unit direction toEye (from the point to
// the eye). With a headlight the half vector equals toEye. Back faces (n facing away) get the
// back albedo and the flipped normal. Writes linear RGB in [0, 1].
inline void shade(const Vec3& n, const Vec3& toEye, float rgb[3]) {
  double ndotv = dot(n, toEye);
  const float* albedo = ndotv >= 0 ? kFrontAlbedo : kBackAlbedo;
  double c = std::fabs(ndotv);
  double spec = std::pow(c, static_cast<double>(kShininess));
  for (int i = 0; i < 3; ++i) {
    double value = srgbToLinear(albedo[i]) * (kAmbient + kDiffuse * c) + kSpecular * spec;
    rgb[i] = static_cast<float>(std::clamp(value, 0.0, 1.0));
  }
}

}  // namespace limn::render::shading
