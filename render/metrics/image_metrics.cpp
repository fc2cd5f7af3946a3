// compareColor(), colorDifference(), compareDepth(), compareNormals(): per-pixel differences
// between two renderings of the same camera, over the pixels DESIGN.md names (covered in either /
// in both).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "render/metrics/metrics.h"

namespace limn::render::metrics {

namespace {

// PSNR of identical images is infinite; JSON has no infinity, so identical colour reports this.
constexpr double kMaxPsnr = 100.0;
constexpr double kPi = 3.14159265358979323846;

const Image& requirePass(const ImageSet& set, const char* name, int minChannels, const char* side) {
  const Image* image = set.find(name);
  if (!image) {
    throw std::invalid_argument(std::string("metrics: the ") + side + " images have no '" + name +
                                "' pass");
  }
  if (image->channels < minChannels ||
      image->pixels.size() != static_cast<size_t>(image->width) * image->height * image->channels) {
    throw std::invalid_argument(std::string("metrics: the ") + side + " '" + name +
                                "' pass needs at least " + std::to_string(minChannels) +
                                " channels");
  }
  return *image;
}

void requireSameSize(const Image& a, const Image& b, const char* name) {
  if (a.width != b.width || a.height != b.height) {
    throw std::invalid_argument(std::string("metrics: the '") + name + "' passes differ in size: " +
                                std::to_string(a.width) + "x" + std::to_string(a.height) + " vs " +
                                std::to_string(b.width) + "x" + std::to_string(b.height));
  }
}

// Which pixels a rendering covers: its mask pass; without one, the colour's alpha; without
// either, non-zero depth (depth 0 means empty).
std::vector<uint8_t> coveredPixels(const ImageSet& set, int width, int height, const char* side) {
  const size_t count = static_cast<size_t>(width) * height;
  std::vector<uint8_t> covered(count, 0);
  const Image* source = set.find(pass::kMask);
  int channel = 0;
  if (!source) {
    const Image* color = set.find(pass::kColor);
    if (color && color->channels >= 4) {
      source = color;
      channel = 3;
    }
  }
  if (!source) source = set.find(pass::kDepth);
  if (!source) {
    throw std::invalid_argument(std::string("metrics: the ") + side +
                                " images have no mask, alpha or depth to tell coverage");
  }
  if (source->width != width || source->height != height ||
      source->pixels.size() != count * source->channels) {
    throw std::invalid_argument(std::string("metrics: the ") + side +
                                " coverage pass differs in size from the compared pass");
  }
  const bool isDepth = source == set.find(pass::kDepth);
  for (size_t i = 0; i < count; ++i) {
    const float value = source->pixels[i * source->channels + channel];
    covered[i] = isDepth ? value > 0.0f : value > 0.5f;
  }
  return covered;
}

// One pass of both image sets, checked to be the same size, with each side's coverage.
struct ComparedPass {
  const Image& a;  // the approximation's
  const Image& b;  // the reference's
  std::vector<uint8_t> coveredA, coveredB;
};

ComparedPass comparePass(const ImageSet& approx, const ImageSet& reference, const char* name,
                         int minChannels) {
  const Image& a = requirePass(approx, name, minChannels, "approximation");
  const Image& b = requirePass(reference, name, minChannels, "reference");
  requireSameSize(a, b, name);
  return {a, b, coveredPixels(approx, a.width, a.height, "approximation"),
          coveredPixels(reference, b.width, b.height, "reference")};
}

}  // namespace

ColorMetrics compareColor(const ImageSet& approx, const ImageSet& reference) {
  const auto [a, b, coveredA, coveredB] = comparePass(approx, reference, pass::kColor, 3);

  double sumSquared = 0;
  size_t pixels = 0;
  for (size_t i = 0; i < coveredA.size(); ++i) {
    if (!coveredA[i] && !coveredB[i]) continue;
    for (int c = 0; c < 3; ++c) {
      const double d = static_cast<double>(a.pixels[i * a.channels + c]) -
                       static_cast<double>(b.pixels[i * b.channels + c]);
      sumSquared += d * d;
    }
    ++pixels;
  }
  ColorMetrics result;
  result.rmse = pixels == 0 ? 0.0 : std::sqrt(sumSquared / (3.0 * static_cast<double>(pixels)));
  // Peak value 1 (colours in [0,1]); capped so identical images give a finite number.
  result.psnr =
      result.rmse > 0 ? std::min(kMaxPsnr, 20.0 * std::log10(1.0 / result.rmse)) : kMaxPsnr;
  return result;
}

namespace {

// A dark-to-bright ramp (black, purple, red, orange, pale yellow, after matplotlib's "inferno"):
// brightness grows with the value, so it reads in grey print too.
std::array<float, 3> heatRamp(double t) {
  static constexpr float kStops[][3] = {{0.00f, 0.00f, 0.02f},
                                        {0.34f, 0.06f, 0.43f},
                                        {0.73f, 0.21f, 0.33f},
                                        {0.98f, 0.55f, 0.04f},
                                        {0.99f, 1.00f, 0.64f}};
  constexpr int kSegments = 4;
  const double x = std::clamp(t, 0.0, 1.0) * kSegments;
  const int i = std::min(static_cast<int>(x), kSegments - 1);
  const float f = static_cast<float>(x - i);
  std::array<float, 3> rgb{};
  for (int c = 0; c < 3; ++c) rgb[c] = kStops[i][c] + f * (kStops[i + 1][c] - kStops[i][c]);
  return rgb;
}

}  // namespace

DiffImage colorDifference(const ImageSet& approx, const ImageSet& reference) {
  const auto [a, b, coveredA, coveredB] = comparePass(approx, reference, pass::kColor, 3);

  constexpr double kSmallestScale = 1.0 / 255.0;          // one step of an 8-bit colour
  std::vector<double> difference(coveredA.size(), -1.0);  // -1: covered in neither
  double scale = kSmallestScale;
  for (size_t i = 0; i < coveredA.size(); ++i) {
    if (!coveredA[i] && !coveredB[i]) continue;
    double d = 0;
    for (int c = 0; c < 3; ++c) {
      d = std::max(d, std::abs(static_cast<double>(a.pixels[i * a.channels + c]) -
                               static_cast<double>(b.pixels[i * b.channels + c])));
    }
    difference[i] = d;
    scale = std::max(scale, d);
  }
  DiffImage result{Image(a.width, a.height, 4), scale};
  for (size_t i = 0; i < difference.size(); ++i) {
    if (difference[i] < 0) continue;  // transparent
    const std::array<float, 3> rgb = heatRamp(difference[i] / scale);
    float* out = &result.image.pixels[i * 4];
    out[0] = rgb[0], out[1] = rgb[1], out[2] = rgb[2], out[3] = 1.0f;
  }
  return result;
}

DepthMetrics compareDepth(const ImageSet& approx, const ImageSet& reference, double diagonal) {
  if (!(diagonal > 0) || !std::isfinite(diagonal)) {
    throw std::invalid_argument("compareDepth: the bounding-box diagonal must be positive, got " +
                                std::to_string(diagonal));
  }
  const auto [a, b, coveredA, coveredB] = comparePass(approx, reference, pass::kDepth, 1);

  double maxDiff = 0, sumDiff = 0;
  size_t pixels = 0;
  for (size_t i = 0; i < coveredA.size(); ++i) {
    if (!coveredA[i] || !coveredB[i]) continue;
    const double d = std::abs(static_cast<double>(a.pixels[i * a.channels]) -
                              static_cast<double>(b.pixels[i * b.channels]));
    maxDiff = std::max(maxDiff, d);
    sumDiff += d;
    ++pixels;
  }
  DepthMetrics result;
  result.maxRel = maxDiff / diagonal;
  result.meanRel = pixels == 0 ? 0.0 : sumDiff / static_cast<double>(pixels) / diagonal;
  return result;
}

NormalMetrics compareNormals(const ImageSet& approx, const ImageSet& reference) {
  const auto [a, b, coveredA, coveredB] = comparePass(approx, reference, pass::kNormal, 3);

  double maxDeg = 0, sumDeg = 0;
  size_t pixels = 0;
  for (size_t i = 0; i < coveredA.size(); ++i) {
    if (!coveredA[i] || !coveredB[i]) continue;
    const float* pa = &a.pixels[i * a.channels];
    const float* pb = &b.pixels[i * b.channels];
    const Vec3 na = normalize(Vec3(pa[0], pa[1], pa[2]));
    const Vec3 nb = normalize(Vec3(pb[0], pb[1], pb[2]));
    // A covered pixel without a normal has no angle to report; it is left out, not counted as 0.
    if (dot(na, na) == 0 || dot(nb, nb) == 0) continue;
    // atan2 of sine and cosine instead of acos of a clamped dot product: the same angle, but
    // accurate for the small angles this metric is about (acos loses half its digits near 1).
    const double deg = std::atan2(length(cross(na, nb)), dot(na, nb)) * (180.0 / kPi);
    maxDeg = std::max(maxDeg, deg);
    sumDeg += deg;
    ++pixels;
  }
  NormalMetrics result;
  result.maxDeg = maxDeg;
  result.meanDeg = pixels == 0 ? 0.0 : sumDeg / static_cast<double>(pixels);
  return result;
}

}  // namespace limn::render::metrics
