// What the colour pictures show where the surface does not cover them. Every colour-like pass
// (colour, wireframe, overlays, the patch image; the reference's colour too) is drawn over
// shading::kBackground with alpha = the pixel's coverage: an anti-aliased edge pixel holds
// a * surface + (1 - a) * kBackground. applyBackground() replaces that background afterwards,
// exactly: by a transparent one (straight, not premultiplied, alpha: the edge pixel becomes
// the surface's colour with alpha a, so a front end can lay the picture over anything) or by an
// opaque colour (alpha 1 everywhere), given in sRGB and laid in linear light like everything
// else (render/core/shading.h). The metrics read the passes before it, so they do not depend on
// the background.
#pragma once

#include <algorithm>
#include <array>

#include "render/core/image.h"
#include "render/core/shading.h"

namespace limn::render {

struct Background {
  bool transparent = true;
  std::array<float, 3> rgb{1.0f, 1.0f, 1.0f};  // the opaque colour, sRGB in [0, 1]
};

// Replaces the background of an RGBA colour-like image; other images are left alone.
inline void applyBackground(Image& image, const Background& background) {
  if (image.channels != 4) return;
  float linear[3];
  for (int c = 0; c < 3; ++c) linear[c] = shading::srgbToLinear(background.rgb[c]);
  for (size_t i = 0; i < image.pixels.size(); i += 4) {
    float* p = &image.pixels[i];
    const float a = p[3];
    if (background.transparent && a <= 0.0f) continue;  // keeps its RGB under alpha 0
    if (a <= 0.0f) {  // all background: exactly the colour asked for
      for (int c = 0; c < 3; ++c) p[c] = linear[c];
      p[3] = 1.0f;
      continue;
    }
    for (int c = 0; c < 3; ++c) {
      const float premultiplied = p[c] - (1.0f - a) * shading::kBackground[c];
      p[c] = background.transparent ? premultiplied / a : premultiplied + (1.0f - a) * linear[c];
      p[c] = std::clamp(p[c], 0.0f, 1.0f);
    }
    if (!background.transparent) p[3] = 1.0f;
  }
}

}  // namespace limn::render
