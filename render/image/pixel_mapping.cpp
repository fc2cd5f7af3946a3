#include "render/image/pixel_mapping.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "render/core/shading.h"

namespace limn::render::image {

namespace {

// v clamped to [0, 1], NaN to 0; without branches, which random-looking pixels mispredict.
float unitClamped(float v) { return std::min(v > 0.0f ? v : 0.0f, 1.0f); }

uint8_t quantize(float v) {
  // Round half away from zero, as std::lround would, without its library call (a tenth of a
  // small request's CPU time went to lround): in double, v * 255 + 0.5 is exact for a float v.
  return static_cast<uint8_t>(static_cast<double>(unitClamped(v)) * 255.0 + 0.5);
}

// The colour passes hold linear light; 8-bit files hold sRGB (render/core/shading.h). Alpha stays
// linear coverage. A table of 4096 linear steps: sRGB's steepest slope (12.92, near black) makes
// a step at most 0.8 of an 8-bit level, and a pow per channel would cost as much as the PNG.
class SrgbTable {
 public:
  SrgbTable() {
    for (int i = 0; i < kSteps; ++i) {
      bytes_[i] = quantize(shading::linearToSrgb(i / float(kSteps - 1)));
    }
  }
  uint8_t operator()(float v) const {
    return bytes_[static_cast<int>(unitClamped(v) * (kSteps - 1) + 0.5f)];  // 0 -> 0, 1 -> 255
  }

 private:
  static constexpr int kSteps = 4096;
  uint8_t bytes_[kSteps];
};

// Pixel by pixel, so that the loop knows which channel is alpha without a modulo per value (a
// small request's colour image is a twentieth of its CPU time here).
std::vector<uint8_t> srgbEncoded(const Image& image) {
  static const SrgbTable srgb;
  std::vector<uint8_t> out(image.pixels.size());
  const float* in = image.pixels.data();
  uint8_t* to = out.data();
  if (image.channels != 4) {
    for (size_t i = 0; i < image.pixels.size(); ++i) to[i] = srgb(in[i]);
    return out;
  }
  for (size_t i = 0; i < image.pixels.size(); i += 4) {
    to[i] = srgb(in[i]);
    to[i + 1] = srgb(in[i + 1]);
    to[i + 2] = srgb(in[i + 2]);
    to[i + 3] = quantize(in[i + 3]);
  }
  return out;
}

std::vector<uint8_t> clamped(const Image& image) {
  std::vector<uint8_t> out(image.pixels.size());
  std::transform(image.pixels.begin(), image.pixels.end(), out.begin(), quantize);
  return out;
}

// Depth: covered pixels (depth > 0) from white (nearest) to kFarthestDepthGrey (farthest).
std::vector<uint8_t> depthGrey(const Image& image) {
  float nearest = std::numeric_limits<float>::infinity();
  float farthest = 0.0f;
  for (size_t i = 0; i < image.pixels.size(); i += image.channels) {
    float d = image.pixels[i];
    if (d > 0.0f && std::isfinite(d)) {
      nearest = std::min(nearest, d);
      farthest = std::max(farthest, d);
    }
  }
  float range = farthest - nearest;
  std::vector<uint8_t> out(image.pixels.size(), 0);
  for (size_t i = 0; i < image.pixels.size(); i += image.channels) {
    float d = image.pixels[i];
    if (!(d > 0.0f) || !std::isfinite(d)) continue;
    float t = range > 0.0f ? (d - nearest) / range : 0.0f;
    out[i] = quantize(1.0f - (1.0f - kFarthestDepthGrey) * t);
  }
  return out;
}

// Normal: RGB = (n + 1) / 2 where the normal has length, black where it is zero (empty).
std::vector<uint8_t> normalRgb(const Image& image) {
  std::vector<uint8_t> out(image.pixels.size(), 0);
  const int c = image.channels;
  for (size_t i = 0; i < image.pixels.size(); i += c) {
    float len2 = 0.0f;
    for (int k = 0; k < std::min(c, 3); ++k) len2 += image.pixels[i + k] * image.pixels[i + k];
    if (!(len2 > 0.0f)) continue;
    for (int k = 0; k < c; ++k) out[i + k] = quantize((image.pixels[i + k] + 1.0f) * 0.5f);
  }
  return out;
}

}  // namespace

std::vector<uint8_t> to8Bit(const Image& image, const std::string& passName) {
  if (passName == pass::kDepth) return depthGrey(image);
  if (passName == pass::kNormal) return normalRgb(image);
  const bool shaded = passName == pass::kColor || passName == pass::kWireframe ||
                      passName == pass::kContours || passName == pass::kCage ||
                      passName == pass::kPatches;
  return shaded ? srgbEncoded(image) : clamped(image);
}

}  // namespace limn::render::image
