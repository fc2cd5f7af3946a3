// Tests of render/metrics: the distance transform against brute force, the silhouette metrics
// on masks whose answers are known by construction, the per-pixel image metrics on hand-made
// ImageSets, and the geometry metric against a real OpenSubdiv limit surface.
#include "render/metrics/metrics.h"

#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <numbers>
#include <random>
#include <stdexcept>
#include <vector>

#include "render/metrics/coverage_distance.h"
#include "render/metrics/outline.h"
#include "render/subdiv/limit_surface.h"
#include "render/tessellate/tessellate.h"
#include "tests/unit/test_meshes.h"

namespace limn::render::metrics {
namespace {

// ---------------------------------------------------------------------------------------------
// Helpers

Mask disc(int size, double cx, double cy, double radius) {
  Mask mask(size, size);
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) {
      const double dx = x + 0.5 - cx, dy = y + 0.5 - cy;
      mask.at(x, y) = dx * dx + dy * dy <= radius * radius;
    }
  }
  return mask;
}

Mask rectangle(int width, int height, int x0, int y0, int x1, int y1) {
  Mask mask(width, height);
  for (int y = y0; y < y1; ++y) {
    for (int x = x0; x < x1; ++x) mask.at(x, y) = 1;
  }
  return mask;
}

bool coveredAt(const Mask& m, int x, int y) {
  return x >= 0 && y >= 0 && x < m.width && y < m.height && m.at(x, y) != 0;
}

// The definition, written out the slow way: covered with an uncovered 4-neighbour or on the
// border.
std::vector<std::pair<int, int>> bruteSilhouette(const Mask& m) {
  std::vector<std::pair<int, int>> out;
  for (int y = 0; y < m.height; ++y) {
    for (int x = 0; x < m.width; ++x) {
      if (!coveredAt(m, x, y)) continue;
      if (!coveredAt(m, x - 1, y) || !coveredAt(m, x + 1, y) || !coveredAt(m, x, y - 1) ||
          !coveredAt(m, x, y + 1)) {
        out.push_back({x, y});
      }
    }
  }
  return out;
}

// Max and sum of the distances from each pixel of `from` to its nearest pixel of `to`.
std::pair<double, double> bruteDirected(const std::vector<std::pair<int, int>>& from,
                                        const std::vector<std::pair<int, int>>& to) {
  double worst = 0, sum = 0;
  for (auto [ax, ay] : from) {
    double best = std::numeric_limits<double>::infinity();
    for (auto [bx, by] : to) best = std::min(best, std::hypot(ax - bx, ay - by));
    worst = std::max(worst, best);
    sum += best;
  }
  return {worst, sum};
}

// ---------------------------------------------------------------------------------------------
// Distance transform

TEST(DistanceTransform, MatchesBruteForceOnRandomImages) {
  std::mt19937 rng(12345);
  const int sizes[][2] = {{1, 1}, {1, 17}, {23, 1}, {7, 5}, {31, 29}, {64, 48}, {50, 3}};
  for (auto [w, h] : sizes) {
    for (double density : {0.002, 0.02, 0.2, 0.7}) {
      std::bernoulli_distribution isFeature(density);
      std::vector<bool> features(static_cast<size_t>(w) * h);
      for (size_t i = 0; i < features.size(); ++i) features[i] = isFeature(rng);
      const std::vector<double> edt = squaredDistanceTransform(features, w, h);
      ASSERT_EQ(edt.size(), features.size());
      for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
          double best = std::numeric_limits<double>::infinity();
          for (int fy = 0; fy < h; ++fy) {
            for (int fx = 0; fx < w; ++fx) {
              if (features[fy * w + fx]) {
                best = std::min(best, double((x - fx) * (x - fx) + (y - fy) * (y - fy)));
              }
            }
          }
          ASSERT_EQ(edt[y * w + x], best)
              << "pixel (" << x << "," << y << ") of " << w << "x" << h << " density " << density;
        }
      }
    }
  }
}

TEST(DistanceTransform, SingleFeatureGivesSquaredEuclideanDistance) {
  const int w = 9, h = 6;
  std::vector<bool> features(w * h, false);
  features[2 * w + 7] = true;  // (7, 2)
  const std::vector<double> edt = squaredDistanceTransform(features, w, h);
  EXPECT_EQ(edt[2 * w + 7], 0.0);
  EXPECT_EQ(edt[0], 49.0 + 4.0);
  EXPECT_EQ(edt[5 * w + 0], 49.0 + 9.0);
  EXPECT_EQ(edt[5 * w + 8], 1.0 + 9.0);
}

TEST(DistanceTransform, NoFeatureIsInfinityEverywhere) {
  const std::vector<double> edt = squaredDistanceTransform(std::vector<bool>(12, false), 4, 3);
  for (double d : edt) EXPECT_TRUE(std::isinf(d) && d > 0);
}

TEST(DistanceTransform, RejectsBufferOfWrongSize) {
  EXPECT_THROW(squaredDistanceTransform(std::vector<bool>(11, false), 4, 3), std::invalid_argument);
}

// ---------------------------------------------------------------------------------------------
// Silhouettes

TEST(Silhouette, IdenticalMasksAgreeExactly) {
  const Mask a = disc(200, 100, 100, 60);
  const SilhouetteMetrics m = compareSilhouettes(a, a, 1);
  EXPECT_EQ(m.hausdorffPx, 0.0);
  EXPECT_EQ(m.meanPx, 0.0);
  EXPECT_EQ(m.iou, 1.0);
  EXPECT_EQ(m.mismatchPx, 0);
}

TEST(Silhouette, ConcentricDiscsAreTheirRadiusDifferenceApart) {
  const Mask a = disc(256, 128, 128, 100);
  const Mask b = disc(256, 128, 128, 103);
  const SilhouetteMetrics m = compareSilhouettes(a, b, 1);
  EXPECT_NEAR(m.hausdorffPx, 3.0, 1.0);
  EXPECT_NEAR(m.meanPx, 3.0, 1.0);
  EXPECT_NEAR(m.iou, (100.0 * 100.0) / (103.0 * 103.0), 0.01);
  // The ring between the circles: pi (103^2 - 100^2) pixels.
  EXPECT_NEAR(m.mismatchPx, 3.14159 * (103 * 103 - 100 * 100), 60);
  // Symmetric in its arguments.
  const SilhouetteMetrics r = compareSilhouettes(b, a, 1);
  EXPECT_EQ(r.hausdorffPx, m.hausdorffPx);
  EXPECT_EQ(r.meanPx, m.meanPx);
  EXPECT_EQ(r.iou, m.iou);
  EXPECT_EQ(r.mismatchPx, m.mismatchPx);
}

TEST(Silhouette, ShiftedSquareIsShiftApartInOutputPixels) {
  for (int k : {1, 3, 7}) {
    const Mask a = rectangle(160, 120, 40, 30, 100, 90);
    const Mask b = rectangle(160, 120, 40 + k, 30, 100 + k, 90);
    const SilhouetteMetrics m = compareSilhouettes(a, b, 1);
    EXPECT_DOUBLE_EQ(m.hausdorffPx, k) << "shift " << k;
    EXPECT_GT(m.meanPx, 0.0);
    EXPECT_LT(m.meanPx, k);  // the top and bottom edges mostly overlap
    EXPECT_DOUBLE_EQ(m.iou, (60.0 - k) * 60.0 / ((60.0 + k) * 60.0));
    EXPECT_EQ(m.mismatchPx, 2 * k * 60);
  }
}

TEST(Silhouette, SupersampleDividesDistancesIntoOutputPixels) {
  const int s = 4, k = 6;  // a shift of 6 supersampled pixels is 1.5 output pixels
  const Mask a = rectangle(64 * s, 48 * s, 10 * s, 10 * s, 40 * s, 30 * s);
  const Mask b = rectangle(64 * s, 48 * s, 10 * s + k, 10 * s, 40 * s + k, 30 * s);
  const SilhouetteMetrics m = compareSilhouettes(a, b, s);
  EXPECT_DOUBLE_EQ(m.hausdorffPx, 1.5);
  // a covers output columns 10..39. b starts 6 pixels later: column 10 is empty in b, column 11
  // is 2/4 covered (not a majority), column 40 is full and 41 is 2/4. So columns 10, 11 and 40
  // differ, over 20 rows.
  EXPECT_EQ(m.mismatchPx, 3 * 20);
}

TEST(Silhouette, MatchesBruteForceOnRandomShapes) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    const int w = 24 + trial * 3, h = 40 - trial;
    Mask a(w, h), b(w, h);
    for (Mask* m : {&a, &b}) {
      for (int blob = 0; blob < 3; ++blob) {
        const double cx = unit(rng) * w, cy = unit(rng) * h, r = 2 + unit(rng) * 8;
        for (int y = 0; y < h; ++y) {
          for (int x = 0; x < w; ++x) {
            if (std::hypot(x + 0.5 - cx, y + 0.5 - cy) <= r) m->at(x, y) = 1;
          }
        }
      }
    }
    const auto sa = bruteSilhouette(a), sb = bruteSilhouette(b);
    if (sa.empty() || sb.empty()) continue;
    const auto [maxAB, sumAB] = bruteDirected(sa, sb);
    const auto [maxBA, sumBA] = bruteDirected(sb, sa);
    const SilhouetteMetrics m = compareSilhouettes(a, b, 1);
    EXPECT_NEAR(m.hausdorffPx, std::max(maxAB, maxBA), 1e-12) << "trial " << trial;
    EXPECT_NEAR(m.meanPx, (sumAB + sumBA) / double(sa.size() + sb.size()), 1e-12)
        << "trial " << trial;
  }
}

TEST(Silhouette, ImageBorderCountsAsUncovered) {
  // A mask covering everything has its contour on the border; one that leaves a one-pixel
  // frame has its contour one pixel inside. Every contour pixel of either is 1 pixel from the
  // other contour, except the 4 image corners, sqrt(2) from the inset's corners.
  const Mask full = rectangle(50, 40, 0, 0, 50, 40);
  const Mask inset = rectangle(50, 40, 1, 1, 49, 39);
  EXPECT_EQ(compareSilhouettes(full, full, 1).hausdorffPx, 0.0);
  const SilhouetteMetrics m = compareSilhouettes(full, inset, 1);
  EXPECT_DOUBLE_EQ(m.hausdorffPx, std::sqrt(2.0));
  const int borderPixels = 2 * 50 + 2 * 38, ringPixels = 2 * 48 + 2 * 36;
  EXPECT_DOUBLE_EQ(
      m.meanPx, (borderPixels - 4 + 4 * std::sqrt(2.0) + ringPixels) / (borderPixels + ringPixels));
}

TEST(Silhouette, IouAndMismatchOnHandMadeMasks) {
  // 4x2 output pixels at S = 2 (8x4 mask). Block coverage counts in a / b:
  //   block (0,0): 4 / 4   block (1,0): 3 / 2   block (2,0): 2 / 3   block (3,0): 0 / 1
  //   block (0,1): 1 / 0   others 0 / 0
  Mask a(8, 4), b(8, 4);
  auto set = [](Mask& m, std::initializer_list<std::pair<int, int>> pixels) {
    for (auto [x, y] : pixels) m.at(x, y) = 1;
  };
  set(a, {{0, 0}, {1, 0}, {0, 1}, {1, 1}, {2, 0}, {3, 0}, {2, 1}, {4, 0}, {5, 0}, {0, 2}});
  set(b, {{0, 0}, {1, 0}, {0, 1}, {1, 1}, {2, 0}, {3, 1}, {4, 0}, {5, 0}, {4, 1}, {7, 1}});
  // Both: (0,0) (1,0) (0,1) (1,1) (2,0) (4,0) (5,0) = 7; either: 10 + 10 - 7 = 13.
  const SilhouetteMetrics m = compareSilhouettes(a, b, 2);
  EXPECT_DOUBLE_EQ(m.iou, 7.0 / 13.0);
  // Majority (> 2 of 4): a covers blocks (0,0) and (1,0); b covers (0,0) and (2,0).
  EXPECT_EQ(m.mismatchPx, 2);
}

TEST(Silhouette, EmptyMasks) {
  const Mask empty(40, 30);
  const SilhouetteMetrics both = compareSilhouettes(empty, empty, 2);
  EXPECT_EQ(both.hausdorffPx, 0.0);
  EXPECT_EQ(both.meanPx, 0.0);
  EXPECT_EQ(both.iou, 1.0);
  EXPECT_EQ(both.mismatchPx, 0);

  // Object in one image only: the distance is the image diagonal in output pixels (20 x 15).
  const Mask some = rectangle(40, 30, 10, 10, 20, 20);
  const SilhouetteMetrics one = compareSilhouettes(some, empty, 2);
  EXPECT_DOUBLE_EQ(one.hausdorffPx, 25.0);
  EXPECT_EQ(one.iou, 0.0);
  EXPECT_EQ(one.mismatchPx, 25);
  EXPECT_DOUBLE_EQ(compareSilhouettes(empty, some, 2).hausdorffPx, 25.0);
}

TEST(Silhouette, RejectsMismatchedMasks) {
  EXPECT_THROW(compareSilhouettes(Mask(8, 8), Mask(8, 4), 1), std::invalid_argument);
  EXPECT_THROW(compareSilhouettes(Mask(8, 8), Mask(8, 8), 3), std::invalid_argument);
  EXPECT_THROW(compareSilhouettes(Mask(8, 8), Mask(8, 8), 0), std::invalid_argument);
  Mask short8(8, 8);  // a byte short of its size
  short8.covered.pop_back();
  EXPECT_THROW(compareSilhouettes(short8, short8, 1), std::invalid_argument);
}

// Not a timed test (that would fail on a slow day): it checks the answer at the largest size
// the service uses by default (1024^2 output at S = 4) and prints how long it took.
TEST(Silhouette, LargeSupersampledMasks) {
  const int s = 4, size = 1024 * s;
  const Mask a = disc(size, size / 2.0, size / 2.0, 1500.0);
  const Mask b = disc(size, size / 2.0 + 0.3, size / 2.0, 1504.0);
  const auto start = std::chrono::steady_clock::now();
  const SilhouetteMetrics m = compareSilhouettes(a, b, s);
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  std::printf("compareSilhouettes %dx%d (S=%d): %.1f ms\n", size, size, s, ms);
  RecordProperty("compareSilhouettesMs", std::to_string(ms));
  EXPECT_NEAR(m.hausdorffPx, 4.3 / s, 1.0 / s);
  EXPECT_NEAR(m.iou, (1500.0 * 1500.0) / (1504.0 * 1504.0), 1e-3);
}

// ---------------------------------------------------------------------------------------------
// Color, depth, normals

// A w x h rendering with a mask pass and uniform passes.
ImageSet rendering(int w, int h) {
  ImageSet set;
  set.passes[pass::kMask] = Image(w, h, 1, 1.0f);
  Image color(w, h, 4, 0.5f);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) color.at(x, y, 3) = 1.0f;
  }
  set.passes[pass::kColor] = color;
  set.passes[pass::kDepth] = Image(w, h, 1, 3.0f);
  Image normal(w, h, 3);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) normal.at(x, y, 2) = 1.0f;
  }
  set.passes[pass::kNormal] = normal;
  return set;
}

TEST(Color, RmseOverPixelsCoveredInEither) {
  ImageSet a = rendering(2, 2), b = rendering(2, 2);
  // Pixel (1,1) is covered in neither: its huge difference must not count.
  a.passes[pass::kMask].at(1, 1) = 0;
  b.passes[pass::kMask].at(1, 1) = 0;
  b.passes[pass::kColor].at(1, 1, 0) = 1.0f;
  // Pixel (1,0) is covered only in the reference: it counts.
  a.passes[pass::kMask].at(1, 0) = 0;
  b.passes[pass::kColor].at(1, 0, 0) = 0.8f;
  // Alpha differs too, but only RGB counts.
  b.passes[pass::kColor].at(0, 0, 3) = 0.0f;
  const ColorMetrics m = compareColor(a, b);
  // One channel of three pixels off by 0.3: sqrt(0.09 / 9) = 0.1, PSNR 20 dB.
  EXPECT_NEAR(m.rmse, 0.1, 1e-6);
  EXPECT_NEAR(m.psnr, 20.0, 1e-4);
}

TEST(Color, WithoutMaskPassAlphaTellsCoverage) {
  ImageSet a = rendering(2, 1), b = rendering(2, 1);
  a.passes.erase(pass::kMask);
  b.passes.erase(pass::kMask);
  a.passes.erase(pass::kDepth);
  b.passes.erase(pass::kDepth);
  a.passes[pass::kColor].at(1, 0, 3) = 0.0f;  // uncovered in both
  b.passes[pass::kColor].at(1, 0, 3) = 0.0f;
  b.passes[pass::kColor].at(1, 0, 1) = 0.0f;
  b.passes[pass::kColor].at(0, 0, 2) = 0.5f + 0.2f;
  EXPECT_NEAR(compareColor(a, b).rmse, std::sqrt(0.04 / 3), 1e-6);
}

TEST(ColorDifference, HeatMapScaledToTheLargestDifference) {
  ImageSet a = rendering(3, 1), b = rendering(3, 1);
  a.passes[pass::kMask].at(2, 0) = 0;  // pixel 2 covered in neither: transparent
  b.passes[pass::kMask].at(2, 0) = 0;
  b.passes[pass::kColor].at(2, 0, 0) = 1.0f;  // ... whatever its colour
  b.passes[pass::kColor].at(0, 0, 1) = 0.9f;  // pixel 0 off by 0.4 in green: the largest
  b.passes[pass::kColor].at(1, 0, 2) = 0.6f;  // pixel 1 off by 0.1 in blue
  const DiffImage diff = colorDifference(a, b);
  EXPECT_NEAR(diff.scale, 0.4, 1e-6);
  ASSERT_EQ(diff.image.channels, 4);
  EXPECT_EQ(diff.image.at(2, 0, 3), 0.0f);
  EXPECT_EQ(diff.image.at(0, 0, 3), 1.0f);
  EXPECT_EQ(diff.image.at(1, 0, 3), 1.0f);
  // The top of the ramp is bright, a quarter of it dark; brightness grows with the difference.
  auto brightness = [&](int x) {
    return diff.image.at(x, 0, 0) + diff.image.at(x, 0, 1) + diff.image.at(x, 0, 2);
  };
  EXPECT_GT(brightness(0), 2.5f);
  EXPECT_LT(brightness(1), 1.0f);
  EXPECT_GT(brightness(1), 0.0f);
}

TEST(ColorDifference, IdenticalImagesAreTheDarkEndWithTheSmallestScale) {
  const ImageSet a = rendering(2, 2);
  const DiffImage diff = colorDifference(a, a);
  EXPECT_NEAR(diff.scale, 1.0 / 255.0, 1e-12);
  EXPECT_LT(diff.image.at(1, 1, 0) + diff.image.at(1, 1, 1) + diff.image.at(1, 1, 2), 0.05f);
  EXPECT_THROW(colorDifference(a, rendering(3, 2)), std::invalid_argument);
}

TEST(Color, IdenticalImagesHaveCappedPsnr) {
  const ImageSet a = rendering(3, 3);
  const ColorMetrics m = compareColor(a, a);
  EXPECT_EQ(m.rmse, 0.0);
  EXPECT_EQ(m.psnr, 100.0);
}

TEST(Color, MissingOrMismatchedPassesAreRejected) {
  ImageSet a = rendering(2, 2), b = rendering(2, 2);
  b.passes.erase(pass::kColor);
  EXPECT_THROW(compareColor(a, b), std::invalid_argument);
  EXPECT_THROW(compareColor(a, rendering(3, 2)), std::invalid_argument);
}

TEST(Depth, RelativeToDiagonalOverPixelsCoveredInBoth) {
  ImageSet a = rendering(2, 2), b = rendering(2, 2);
  b.passes[pass::kDepth].at(0, 0) = 3.5f;   // covered in both: counts
  b.passes[pass::kDepth].at(1, 0) = 3.25f;  // covered in both: counts
  a.passes[pass::kMask].at(0, 1) = 0;       // covered in the reference only: ignored
  b.passes[pass::kDepth].at(0, 1) = 9.0f;
  const DepthMetrics m = compareDepth(a, b, 2.0);
  EXPECT_NEAR(m.maxRel, 0.25, 1e-7);
  EXPECT_NEAR(m.meanRel, (0.5 + 0.25) / 3 / 2.0, 1e-7);
  EXPECT_THROW(compareDepth(a, b, 0.0), std::invalid_argument);
}

TEST(Normals, AngleBetweenNormalisedNormals) {
  ImageSet a = rendering(3, 1), b = rendering(3, 1);
  Image& na = a.passes[pass::kNormal];
  Image& nb = b.passes[pass::kNormal];
  // (0,0,1) vs (1,0,0): 90 degrees.
  nb.at(0, 0, 0) = 1, nb.at(0, 0, 2) = 0;
  // Unnormalised (0,0,2) vs (0,1,1): 45 degrees.
  na.at(1, 0, 2) = 2, nb.at(1, 0, 1) = 1;
  // A tiny angle, measured accurately: 1e-4 radians.
  nb.at(2, 0, 1) = static_cast<float>(std::tan(1e-4));
  const NormalMetrics m = compareNormals(a, b);
  EXPECT_NEAR(m.maxDeg, 90.0, 1e-4);
  EXPECT_NEAR(m.meanDeg, (90.0 + 45.0 + 1e-4 * 180.0 / M_PI) / 3, 1e-4);

  // Opposite normals: 180 degrees, not NaN.
  ImageSet c = rendering(1, 1), d = rendering(1, 1);
  d.passes[pass::kNormal].at(0, 0, 2) = -1;
  EXPECT_NEAR(compareNormals(c, d).maxDeg, 180.0, 1e-9);
}

TEST(Normals, SmallAnglePrecision) {
  ImageSet a = rendering(1, 1), b = rendering(1, 1);
  b.passes[pass::kNormal].at(0, 0, 0) = static_cast<float>(std::tan(1e-4));
  EXPECT_NEAR(compareNormals(a, b).maxDeg, 1e-4 * 180.0 / M_PI, 1e-7);
}

// ---------------------------------------------------------------------------------------------
// Geometry against a real OpenSubdiv limit surface

// Builds a TriangleMesh triangle by triangle: each corner at the limit position of its (u, v)
// on `face`, plus `offset`.
struct TriangleMeshBuilder {
  const subdiv::LimitSurface& surface;
  tessellate::TriangleMesh mesh;
  Vec3 offset{0, 0, 0};

  void add(int face, Vec2 a, Vec2 b, Vec2 c) {
    for (Vec2 uv : {a, b, c}) {
      mesh.indices.push_back(static_cast<uint32_t>(mesh.positions.size()));
      mesh.positions.push_back(Vec3f(surface.position(face, uv.x, uv.y) + offset));
      mesh.cornerUVs.push_back({static_cast<float>(uv.x), static_cast<float>(uv.y)});
    }
    mesh.triangleFaces.push_back(face);
  }
  // An n x n grid of quads over [u0,u1] x [v0,v1], two triangles each.
  void addGrid(int face, int n, double u0 = 0, double v0 = 0, double u1 = 1, double v1 = 1) {
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        const double ua = u0 + (u1 - u0) * i / n, ub = u0 + (u1 - u0) * (i + 1) / n;
        const double va = v0 + (v1 - v0) * j / n, vb = v0 + (v1 - v0) * (j + 1) / n;
        add(face, {ua, va}, {ub, va}, {ub, vb});
        add(face, {ua, va}, {ub, vb}, {ua, vb});
      }
    }
  }
};

// Float positions put every vertex up to ~1e-7 (relative) off the surface.
constexpr double kFloatNoise = 1e-6;

// The points measureGeometry measures on each triangle (DESIGN.md): barycentric weights of its
// corners, edge midpoints and centroid.
constexpr double kSevenPoints[7][3] = {{1, 0, 0},
                                       {0, 1, 0},
                                       {0, 0, 1},
                                       {.5, .5, 0},
                                       {0, .5, .5},
                                       {.5, 0, .5},
                                       {1. / 3, 1. / 3, 1. / 3}};

TEST(Geometry, FlatFaceIsMeasuredExactlyAtInterpolatedParameters) {
  // On a flat, uniform grid the Catmull-Clark limit of an interior face is the bilinear map of
  // its corners, so triangles of limit points lie on the surface at the barycentric blend of
  // their corners' (u, v): anything but ~0 means positions and parameters were blended apart.
  const subdiv::LimitSurface surface(testing::grid(4, 0.0));
  const int interiorFace = 5;
  TriangleMeshBuilder builder{surface, {}};
  builder.addGrid(interiorFace, 3);
  builder.add(interiorFace, {0.1, 0.2}, {0.9, 0.3}, {0.4, 0.95});
  const GeometryMetrics exact = measureGeometry(builder.mesh, surface);
  EXPECT_LT(exact.maxDist, kFloatNoise);

  // The same mesh lifted 0.01 off the plane: every sample is exactly that far.
  TriangleMeshBuilder lifted{surface, {}, {0, 0, 0.01}};
  lifted.addGrid(interiorFace, 3);
  const GeometryMetrics m = measureGeometry(lifted.mesh, surface);
  EXPECT_NEAR(m.maxDist, 0.01, kFloatNoise);
  EXPECT_NEAR(m.meanDist, 0.01, kFloatNoise);
  EXPECT_NEAR(m.relMaxDist, 0.01 / surface.bounds().diagonal(), kFloatNoise);
}

TEST(Geometry, ChordsOfACurvedFaceLeaveTheSurfaceAndShrinkWithRefinement) {
  const subdiv::LimitSurface surface(testing::cube());
  const int face = 0;
  TriangleMeshBuilder coarse{surface, {}};
  coarse.add(face, {0, 0}, {1, 0}, {1, 1});
  coarse.add(face, {0, 0}, {1, 1}, {0, 1});
  const GeometryMetrics one = measureGeometry(coarse.mesh, surface);
  // The cube's limit surface bulges: two triangles spanning a face cut well inside it, but by
  // less than the face is wide.
  EXPECT_GT(one.maxDist, 0.01);
  EXPECT_LT(one.maxDist, 0.2);
  EXPECT_GT(one.meanDist, 0.0);
  EXPECT_LT(one.meanDist, one.maxDist);
  EXPECT_DOUBLE_EQ(one.relMaxDist, one.maxDist / surface.bounds().diagonal());

  // The largest of the seven samples, worked out here independently.
  double worst = 0;
  for (size_t t = 0; t < coarse.mesh.triangleCount(); ++t) {
    for (const auto& w : kSevenPoints) {
      Vec3 p{0, 0, 0};
      double u = 0, v = 0;
      for (int k = 0; k < 3; ++k) {
        p += coarse.mesh.positions[coarse.mesh.indices[3 * t + k]].toDouble() * w[k];
        u += coarse.mesh.cornerUVs[3 * t + k].x * w[k];
        v += coarse.mesh.cornerUVs[3 * t + k].y * w[k];
      }
      worst = std::max(worst, length(p - surface.position(face, u, v)));
    }
  }
  EXPECT_NEAR(one.maxDist, worst, 1e-12);

  // Chord error falls with the square of the edge length: 8x finer, ~64x closer.
  TriangleMeshBuilder fine{surface, {}};
  fine.addGrid(face, 8);
  const GeometryMetrics eight = measureGeometry(fine.mesh, surface);
  EXPECT_GT(eight.maxDist, 0.0);
  EXPECT_LT(eight.maxDist, one.maxDist / 20);
}

// Indexed like a real tessellation: vertices shared by the triangles of a face.
tessellate::TriangleMesh sharedGrid(const subdiv::LimitSurface& surface, int face, int n) {
  tessellate::TriangleMesh mesh;
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) {
      mesh.positions.push_back(Vec3f(surface.position(face, double(i) / n, double(j) / n)));
    }
  }
  auto uv = [&](int i, int j) { return Vec2f{float(i) / n, float(j) / n}; };
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const uint32_t a = j * (n + 1) + i, b = a + 1, c = a + n + 2, d = a + n + 1;
      mesh.indices.insert(mesh.indices.end(), {a, b, c, a, c, d});
      mesh.cornerUVs.insert(mesh.cornerUVs.end(), {uv(i, j), uv(i + 1, j), uv(i + 1, j + 1),
                                                   uv(i, j), uv(i + 1, j + 1), uv(i, j + 1)});
      mesh.triangleFaces.insert(mesh.triangleFaces.end(), {face, face});
    }
  }
  return mesh;
}

TEST(Geometry, SharedVerticesCountOncePerCorner) {
  // The same triangles, once with vertices shared and once with every corner its own vertex,
  // measure the same: a shared vertex still counts once per corner.
  const subdiv::LimitSurface surface(testing::cube());
  const tessellate::TriangleMesh shared = sharedGrid(surface, 2, 5);
  TriangleMeshBuilder separate{surface, {}};
  separate.addGrid(2, 5);
  const GeometryMetrics a = measureGeometry(shared, surface);
  const GeometryMetrics b = measureGeometry(separate.mesh, surface);
  EXPECT_GT(a.maxDist, 0.0);
  EXPECT_NEAR(a.maxDist, b.maxDist, 1e-12);
  EXPECT_NEAR(a.meanDist, b.meanDist, 1e-12);

  // A vertex shared with a triangle of another face, whose parameters there point elsewhere:
  // that corner is measured at its own (face, u, v).
  tessellate::TriangleMesh mesh = sharedGrid(surface, 0, 1);  // vertex 0 at face 0, (0, 0)
  mesh.positions.push_back(Vec3f(surface.position(1, 1, 0)));
  mesh.positions.push_back(Vec3f(surface.position(1, 1, 1)));
  mesh.indices.insert(mesh.indices.end(), {0, 4, 5});
  mesh.cornerUVs.insert(mesh.cornerUVs.end(), {{0.5f, 0.5f}, {1, 0}, {1, 1}});
  mesh.triangleFaces.push_back(1);
  const double misplaced = length(surface.position(0, 0, 0) - surface.position(1, 0.5, 0.5));
  EXPECT_GE(measureGeometry(mesh, surface).maxDist, misplaced - kFloatNoise);
}

TEST(Geometry, VerticesAgainstTheirOwnLimitPositions) {
  const subdiv::LimitSurface surface(testing::cube());
  tessellate::TriangleMesh mesh;
  for (const Vec3& p : surface.controlLimitPositions()) {
    mesh.positions.push_back(Vec3f(p));
    mesh.limitPositions.push_back(Vec3f(p));
  }
  mesh.indices = {0, 1, 3, 0, 3, 2};
  EXPECT_EQ(measureGeometry(mesh, surface).maxDist, 0.0);

  // Cage vertices measured against their limits: the cube's corners sit well outside.
  tessellate::TriangleMesh cage = mesh;
  for (size_t v = 0; v < cage.positions.size(); ++v) {
    cage.positions[v] = Vec3f(surface.mesh().points[v]);
  }
  const double expected = length(surface.mesh().points[0] - surface.controlLimitPositions()[0]);
  const GeometryMetrics m = measureGeometry(cage, surface);
  EXPECT_NEAR(m.maxDist, expected, kFloatNoise);  // all eight corners are alike
  EXPECT_NEAR(m.meanDist, expected, kFloatNoise);

  // One vertex moved by 0.05: max 0.05, mean 0.05 / 8.
  mesh.positions[4].y += 0.05f;
  const GeometryMetrics one = measureGeometry(mesh, surface);
  EXPECT_NEAR(one.maxDist, 0.05, kFloatNoise);
  EXPECT_NEAR(one.meanDist, 0.05 / 8, kFloatNoise);
}

TEST(Geometry, TrianglesAcrossSubFacesAreMeasuredAtTheirCorners) {
  // Catmull-Clark triangles are parameterised as three quad sub-faces on separate tiles of
  // (u, v); a triangle from a corner of one tile to a corner of another has no meaningful
  // midpoint parameters, so only its corners count.
  const subdiv::LimitSurface surface(testing::octahedron());
  const int face = 0;
  ASSERT_TRUE(surface.parameterization(face).HasSubFaces());
  TriangleMeshBuilder across{surface, {}};
  across.add(face, surface.cornerUV(face, 0), surface.cornerUV(face, 1), surface.centerUV(face));
  across.add(face, surface.cornerUV(face, 1), surface.cornerUV(face, 2), surface.centerUV(face));
  EXPECT_LT(measureGeometry(across.mesh, surface).maxDist, kFloatNoise);

  // Inside one sub-face (tile 0 spans [0, 0.5]^2: corner, edge midpoints, centre) the samples
  // are all measured, and the curved surface leaves the chords.
  TriangleMeshBuilder inside{surface, {}};
  inside.add(face, {0, 0}, {0.5, 0}, {0.5, 0.5});
  inside.add(face, {0, 0}, {0.5, 0.5}, {0, 0.5});
  const GeometryMetrics m = measureGeometry(inside.mesh, surface);
  EXPECT_GT(m.maxDist, 1e-4);
  EXPECT_LT(m.maxDist, 0.2);
}

TEST(Geometry, MeshWithoutLimitInformationIsRejected) {
  const subdiv::LimitSurface surface(testing::cube());
  tessellate::TriangleMesh mesh;
  mesh.positions = {Vec3f(0, 0, 0), Vec3f(1, 0, 0), Vec3f(0, 1, 0)};
  mesh.indices = {0, 1, 2};
  EXPECT_THROW(measureGeometry(mesh, surface), std::invalid_argument);
  // An empty mesh measures nothing.
  EXPECT_EQ(measureGeometry(tessellate::TriangleMesh{}, surface).maxDist, 0.0);
}

// ---------------------------------------------------------------------------------------------
// Continuous outline distances (outline.h): analytic shapes, with the coverage query answering
// exactly where the shape is, and masks sampled from the same shapes.

using Shape = std::function<bool(double x, double y)>;

Mask sampleMask(const Shape& inside, int size, int s) {
  Mask mask(size * s, size * s);
  for (int j = 0; j < size * s; ++j) {
    for (int i = 0; i < size * s; ++i) mask.at(i, j) = inside((i + 0.5) / s, (j + 0.5) / s);
  }
  return mask;
}

CoverageQuery queryOf(const Shape& inside) {
  return [inside](const std::vector<Vec2>& points, std::vector<char>& covered) {
    covered.resize(points.size());
    for (size_t k = 0; k < points.size(); ++k) covered[k] = inside(points[k].x, points[k].y);
  };
}

Outline outlineOf(const Shape& inside, int size, int s) {
  return locateOutline(sampleMask(inside, size, s), s, queryOf(inside), CancelToken{});
}

Shape discAt(double cx, double cy, double r) {
  return [=](double x, double y) { return (x - cx) * (x - cx) + (y - cy) * (y - cy) < r * r; };
}

TEST(Outline, PointsLieOnTheCurveToTheTolerance) {
  const double cx = 40.3, cy = 37.8, r = 21.7;
  Outline o = outlineOf(discAt(cx, cy, r), 80, 4);
  ASSERT_GT(o.points.size(), 500u);
  for (Vec2 p : o.points) EXPECT_NEAR(std::hypot(p.x - cx, p.y - cy), r, kOutlineTolerancePx);
  // A closed curve: every crossing joins two segments.
  std::vector<int> degree(o.points.size(), 0);
  for (auto [a, b] : o.segments) ++degree[a], ++degree[b];
  for (int d : degree) EXPECT_EQ(d, 2);
}

TEST(Outline, DiscShiftedByThreeTenthsOfAPixel) {
  for (int s : {1, 4, 8}) {
    Outline a = outlineOf(discAt(50.2, 49.6, 30.0), 100, s);
    Outline b = outlineOf(discAt(50.5, 49.6, 30.0), 100, s);
    OutlineDistances d = compareOutlines(a, b, 141.0);
    EXPECT_NEAR(d.hausdorffPx, 0.3, 0.01) << "S = " << s;
    // The mean of |0.3 cos(theta)| around the circle is 0.6 / pi.
    EXPECT_NEAR(d.meanPx, 0.6 / std::numbers::pi, 0.01) << "S = " << s;
  }
}

TEST(Outline, SquareAgainstItselfIsZero) {
  Shape square = [](double x, double y) { return x > 10.37 && x < 52.81 && y > 12.02 && y < 49.5; };
  Outline a = outlineOf(square, 64, 4);
  ASSERT_FALSE(a.empty());
  OutlineDistances d = compareOutlines(a, a, 90.0);
  EXPECT_EQ(d.hausdorffPx, 0.0);
  EXPECT_EQ(d.meanPx, 0.0);
  // Located from a mask at another supersampling, the same square agrees along its sides to the
  // tolerance; at its corners the polyline may cut the corner by a sixth of a cell at most.
  OutlineDistances d8 = compareOutlines(a, outlineOf(square, 64, 8), 90.0);
  EXPECT_LT(d8.hausdorffPx, 0.25 / 6);
  EXPECT_LT(d8.meanPx, 2 * kOutlineTolerancePx);
}

TEST(Outline, SubQuantumShiftsAreSeenWhereMaskMetricsReadZero) {
  // 0.05 px is below a supersampled pixel at S = 4: the mask metric cannot tell, this can.
  Shape a = discAt(32.0, 32.0, 20.0), b = discAt(32.05, 32.0, 20.0);
  OutlineDistances d = compareOutlines(outlineOf(a, 64, 4), outlineOf(b, 64, 4), 90.0);
  EXPECT_NEAR(d.hausdorffPx, 0.05, 0.005);
}

TEST(Outline, OneSidedOutlineIsFarAndBothEmptyIsZero) {
  Outline none = outlineOf([](double, double) { return false; }, 32, 4);
  Outline full = outlineOf([](double, double) { return true; }, 32, 4);
  EXPECT_TRUE(none.empty());
  EXPECT_TRUE(full.empty());  // the image frame is not an outline
  Outline disc = outlineOf(discAt(16, 16, 8), 32, 4);
  EXPECT_EQ(compareOutlines(none, full, 45.0).hausdorffPx, 0.0);
  EXPECT_EQ(compareOutlines(disc, none, 45.0).hausdorffPx, 45.0);
  EXPECT_EQ(compareOutlines(none, disc, 45.0).meanPx, 45.0);
}

TEST(Outline, MissingPieceIsItsDistanceAway) {
  // Two discs against one of them: the second disc's outline is as far from the first's as the
  // gap between the two circles.
  Shape one = discAt(20, 32, 10), two = [](double x, double y) {
    return discAt(20, 32, 10)(x, y) || discAt(50, 32, 6)(x, y);
  };
  OutlineDistances d = compareOutlines(outlineOf(one, 64, 4), outlineOf(two, 64, 4), 90.0);
  EXPECT_NEAR(d.hausdorffPx, 50 + 6 - 30, 0.01);  // the far side of the second disc
}

// A pinhole or sliver that only one sample caught, thinner than the reference can resolve
// (resolvablePx, twice its accuracy), is not measured: it is as likely in either picture. A
// thicker one, or a thin notch that is part of a larger outline, still counts by its reach.
TEST(Outline, LoopsThinnerThanTheReferenceResolvesAreLeftOutAndCounted) {
  const Shape disc = discAt(32, 32, 20);
  // Samples at S = 4 lie at (i + 0.5) / 4: x = 20.125 and y = 30.125 is one.
  auto withHole = [&](double width) -> Shape {
    return [=](double x, double y) {
      const bool hole = std::abs(x - 20.125) < width / 2 && y > 30.0 && y < 30.2;
      return disc(x, y) && !hole;
    };
  };
  const Outline whole = outlineOf(disc, 64, 4);
  const Outline pinhole = outlineOf(withHole(0.02), 64, 4);
  ASSERT_GT(pinhole.points.size(), whole.points.size());  // the hole was caught

  OutlineDistances seen = compareOutlines(whole, pinhole, 90.0);
  EXPECT_GT(seen.hausdorffPx, 5.0);  // the hole is far from the disc's rim
  EXPECT_EQ(seen.unresolvedLoops, 0u);
  OutlineDistances resolved = compareOutlines(whole, pinhole, 90.0, nullptr, nullptr, 0.05);
  EXPECT_EQ(resolved.hausdorffPx, 0.0);
  EXPECT_EQ(resolved.unresolvedLoops, 1u);

  const Outline wider = outlineOf(withHole(0.1), 64, 4);
  OutlineDistances kept = compareOutlines(whole, wider, 90.0, nullptr, nullptr, 0.05);
  EXPECT_GT(kept.hausdorffPx, 5.0);
  EXPECT_EQ(kept.unresolvedLoops, 0u);

  // A sliver outside the disc, 0.02 px wide: the same, the other way round.
  const Shape sliver = [&](double x, double y) {
    return disc(x, y) || (std::abs(x - 60.125) < 0.01 && y > 10.0 && y < 10.2);
  };
  OutlineDistances island =
      compareOutlines(outlineOf(sliver, 64, 4), whole, 90.0, nullptr, nullptr, 0.05);
  EXPECT_EQ(island.hausdorffPx, 0.0);
  EXPECT_EQ(island.unresolvedLoops, 1u);

  // A notch as thin, cut 5 px in from the rim, is part of the disc's own outline: it counts.
  const Shape notched = [&](double x, double y) {
    return disc(x, y) && !(std::abs(x - 32.125) < 0.01 && y > 47.0);
  };
  OutlineDistances notch =
      compareOutlines(whole, outlineOf(notched, 64, 4), 90.0, nullptr, nullptr, 0.05);
  EXPECT_NEAR(notch.hausdorffPx, 5.0, 0.2);
  EXPECT_EQ(notch.unresolvedLoops, 0u);
}

TEST(Outline, SaddleCellsFollowTheQuery) {
  // A checkerboard of 1 px squares seen at S = 1: every cell is a saddle, resolved by the query
  // at its centre; every crossing still ends up joined.
  Shape board = [](double x, double y) {
    return (static_cast<int>(std::floor(x)) + static_cast<int>(std::floor(y))) % 2 == 0;
  };
  Outline o = outlineOf(board, 16, 1);
  ASSERT_FALSE(o.empty());
  for (Vec2 p : o.points) {
    double fx = p.x - std::floor(p.x), fy = p.y - std::floor(p.y);
    EXPECT_TRUE(std::min(fx, 1 - fx) < 2e-3 || std::min(fy, 1 - fy) < 2e-3);
  }
  EXPECT_GE(o.segments.size(), o.points.size() - 64);
}

// ---------------------------------------------------------------------------------------------
// Distances to a rendering's geometry (coverage_distance.h): triangles placed in the image plane
// of an orthographic camera, so their projections are known exactly.

// The queries keep a reference to their token.
const CancelToken kNever;

Camera pixelCamera(int width, int height) {
  return Camera({0, 0, 10}, {0, 0, 0}, {0, 1, 0}, 45, Projection::Orthographic, height, width,
                height, 0.1, 100);
}

// Triangles given by their corners in output pixels, placed in front of `camera`.
tessellate::TriangleMesh trianglesAt(const Camera& camera,
                                     const std::vector<std::array<Vec2, 3>>& triangles) {
  tessellate::TriangleMesh mesh;
  for (const auto& corners : triangles) {
    for (const Vec2& p : corners) {
      const Ray ray = camera.rayThrough(p.x, p.y);
      mesh.indices.push_back(static_cast<uint32_t>(mesh.positions.size()));
      mesh.positions.push_back(Vec3f(ray.origin + ray.direction * 5.0));
    }
  }
  return mesh;
}

TEST(CoverageDistance, PointToTriangleInsideOnEdgesAndPastCorners) {
  const Vec2 a{0, 0}, b{4, 0}, c{0, 3};
  EXPECT_EQ(pointTriangleDistance({1, 1}, a, b, c), 0.0);
  EXPECT_EQ(pointTriangleDistance({1, 1}, a, c, b), 0.0);  // either winding
  EXPECT_NEAR(pointTriangleDistance({2, -0.5}, a, b, c), 0.5, 1e-12);
  EXPECT_NEAR(pointTriangleDistance({-3, -4}, a, b, c), 5.0, 1e-12);
  EXPECT_NEAR(pointTriangleDistance({4, 3}, a, b, c), 2.4, 1e-12);  // to the hypotenuse
  // A degenerate triangle is its segment: no inside, and points past its end are not on it.
  EXPECT_NEAR(pointTriangleDistance({6, 0}, a, b, {2, 0}), 2.0, 1e-12);
}

TEST(CoverageDistance, LowersBoundsToTheNearestCoveredPointOnly) {
  const Camera camera = pixelCamera(64, 48);
  // A needle 0.02 px wide along y = 10 from x = 10 to its tip at x = 40, and a square.
  const tessellate::TriangleMesh mesh =
      trianglesAt(camera, {{Vec2{10, 9.99}, Vec2{10, 10.01}, Vec2{40, 10}},
                           {Vec2{30, 30}, Vec2{40, 30}, Vec2{40, 40}},
                           {Vec2{30, 30}, Vec2{40, 40}, Vec2{30, 40}}});
  const CoverageDistanceQuery query = meshCoverageDistance(mesh, camera, kNever);
  const std::vector<Vec2> points = {{25, 10.5}, {43, 10}, {35, 35}, {35, 27}, {5, 45}};
  std::vector<double> distances = {3.0, 3.0, 3.0, 3.0, 1.5};
  query(points, distances);
  EXPECT_NEAR(distances[0], 0.495, 1e-6);  // beside the needle (0.005 px half-wide there)
  EXPECT_NEAR(distances[1], 3.0, 1e-3);    // past its tip: exactly the bound
  EXPECT_EQ(distances[2], 3.0);            // covered, its edge 5 px off: the bound stays
  EXPECT_NEAR(distances[3], 3.0, 1e-3);    // 3 px above the square
  EXPECT_EQ(distances[4], 1.5);            // nothing within the bound
}

// Two rectangles of quads [10, 40] x [10, 20] and [10, 40] x [20 + gap, 30] (two triangles each).
std::vector<std::array<Vec2, 3>> rectanglesApart(double gap, bool splitUpperEdge) {
  const double y = 20 + gap;
  std::vector<std::array<Vec2, 3>> triangles = {{Vec2{10, 10}, Vec2{40, 10}, Vec2{40, 20}},
                                                {Vec2{10, 10}, Vec2{40, 20}, Vec2{10, 20}}};
  if (splitUpperEdge) {  // a corner at (25, y): the edges along the seam do not match
    triangles.push_back({Vec2{10, y}, Vec2{25, y}, Vec2{10, 30}});
    triangles.push_back({Vec2{25, y}, Vec2{40, y}, Vec2{40, 30}});
    triangles.push_back({Vec2{25, y}, Vec2{40, 30}, Vec2{10, 30}});
  } else {
    triangles.push_back({Vec2{10, y}, Vec2{40, y}, Vec2{40, 30}});
    triangles.push_back({Vec2{10, y}, Vec2{40, 30}, Vec2{10, 30}});
  }
  return triangles;
}

TEST(CoverageDistance, CoveredPointsAreMeasuredToGapsTheSamplesMissButNotToSeams) {
  const Camera camera = pixelCamera(64, 48);
  const std::vector<Vec2> points = {{25, 15}, {25, 25}, {25, 19.9}, {5, 5}};
  // A slit 0.02 px wide, between two rows of samples at any S up to 32.
  {
    const tessellate::TriangleMesh mesh = trianglesAt(camera, rectanglesApart(0.02, false));
    std::vector<double> distances = {8.0, 8.0, 3.0, 2.0};
    meshCoverageDistance(mesh, camera, kNever)(points, distances);
    EXPECT_NEAR(distances[0], 5.0, 2e-3);  // to the slit, not to the rectangles' far edges
    EXPECT_NEAR(distances[1], 4.98, 2e-3);
    EXPECT_NEAR(distances[2], 0.1, 2e-3);
    EXPECT_EQ(distances[3], 2.0);  // uncovered, nothing within its bound
  }
  // Touching rectangles: the seam is no gap, whether its edges match or one side has a corner
  // on it.
  for (bool split : {false, true}) {
    const tessellate::TriangleMesh mesh = trianglesAt(camera, rectanglesApart(0, split));
    std::vector<double> distances = {3.0, 3.0, 3.0, 2.0};
    meshCoverageDistance(mesh, camera, kNever)(points, distances);
    EXPECT_EQ(distances[0], 3.0) << split;
    EXPECT_EQ(distances[1], 3.0) << split;
    EXPECT_EQ(distances[2], 3.0) << split;
  }
}

TEST(CoverageDistance, NeedleNarrowerThanTheSamplesIsNotAGapInTheSilhouette) {
  // Output 16 x 16 px at S = 4. Both renderings hold a square [4, 10]^2 and a needle from it to
  // x = 15 along y = 7; rendering A's needle is wide enough for its row of samples, B's lies
  // between two rows of samples, so B's mask has no needle at all.
  constexpr int kSize = 16, kS = 4;
  const Camera camera = pixelCamera(kSize, kSize);
  const std::vector<std::array<Vec2, 3>> square = {{Vec2{4, 4}, Vec2{10, 4}, Vec2{10, 10}},
                                                   {Vec2{4, 4}, Vec2{10, 10}, Vec2{4, 10}}};
  auto withNeedle = [&](double y0, double y1) {
    auto triangles = square;
    triangles.push_back({Vec2{10, y0}, Vec2{10, y1}, Vec2{15, 0.5 * (y0 + y1)}});
    return trianglesAt(camera, triangles);
  };
  const tessellate::TriangleMesh meshA = withNeedle(6.95, 7.3), meshB = withNeedle(7.01, 7.09);
  // The masks as a rasteriser samples them: covered where a sample lies in a triangle.
  auto maskOf = [&](double y0, double y1) {
    auto triangles = square;
    triangles.push_back({Vec2{10, y0}, Vec2{10, y1}, Vec2{15, 0.5 * (y0 + y1)}});
    Mask mask(kSize * kS, kSize * kS);
    for (int j = 0; j < kSize * kS; ++j) {
      for (int i = 0; i < kSize * kS; ++i) {
        const Vec2 p{(i + 0.5) / kS, (j + 0.5) / kS};
        for (const auto& t : triangles) {
          if (pointTriangleDistance(p, t[0], t[1], t[2]) == 0) mask.at(i, j) = 1;
        }
      }
    }
    return mask;
  };
  const Mask maskA = maskOf(6.95, 7.3), maskB = maskOf(7.01, 7.09);
  ASSERT_TRUE(maskA.at(13 * kS, 7 * kS));   // A's needle has samples
  ASSERT_FALSE(maskB.at(13 * kS, 7 * kS));  // B's has none
  const SilhouetteMetrics sampled = compareSilhouettes(maskA, maskB, kS);
  EXPECT_GT(sampled.hausdorffPx, 2.0);  // the samples see a missing needle
  const CoverageDistanceQuery geometryA = meshCoverageDistance(meshA, camera, kNever);
  const CoverageDistanceQuery geometryB = meshCoverageDistance(meshB, camera, kNever);
  const SilhouetteMetrics measured = compareSilhouettes(
      maskA, maskB, kS, CancelToken{}, {.approximation = &geometryA, .reference = &geometryB});
  EXPECT_LT(measured.hausdorffPx, 0.35);  // the needles are a fraction of a pixel apart
  EXPECT_LT(measured.meanPx, sampled.meanPx);
  // A real difference stays: B without its needle is the needle's length from A.
  const tessellate::TriangleMesh squareOnly = trianglesAt(camera, square);
  const CoverageDistanceQuery geometrySquare = meshCoverageDistance(squareOnly, camera, kNever);
  const SilhouetteMetrics missing = compareSilhouettes(
      maskA, maskB, kS, CancelToken{}, {.approximation = &geometryA, .reference = &geometrySquare});
  // (to the square's edge itself, not to its samples' centres: up to half a sample nearer)
  EXPECT_GT(missing.hausdorffPx, 4.5);
  EXPECT_NEAR(missing.hausdorffPx, sampled.hausdorffPx, 0.5 / kS);
}

// The search near each contour pixel must give exactly the transform's numbers: the same
// integer squared distances, summed in the same order. Random blobs, shifted by 0 to 90 mask
// pixels (past the 64 rows the search looks at, so it also hands some directions to the
// transform), with and without the renderings' geometry.
TEST(Silhouette, NearbySearchGivesTheTransformsNumbersExactly) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  constexpr int kS = 4, kSize = 96;
  const Camera camera = pixelCamera(kSize, kSize);
  for (int trial = 0; trial < 24; ++trial) {
    const double shift = (trial % 6) * 18.0 / kS;  // output pixels
    Mask a(kSize * kS, kSize * kS), b(kSize * kS, kSize * kS);
    std::vector<std::array<Vec2, 3>> trianglesA, trianglesB;
    for (int blob = 0; blob < 3; ++blob) {
      const double cx = 20 + unit(rng) * 50, cy = 20 + unit(rng) * 50, r = 3 + unit(rng) * 15;
      const double rb = r * (0.97 + 0.06 * unit(rng));
      for (int j = 0; j < kSize * kS; ++j) {
        for (int i = 0; i < kSize * kS; ++i) {
          const double x = (i + 0.5) / kS, y = (j + 0.5) / kS;
          if (std::hypot(x - cx, y - cy) <= r) a.at(i, j) = 1;
          if (std::hypot(x - cx - shift, y - cy + 0.3 * shift) <= rb) b.at(i, j) = 1;
        }
      }
      trianglesA.push_back({Vec2{cx - r, cy - r}, Vec2{cx + r, cy - r}, Vec2{cx, cy + r}});
      trianglesB.push_back(
          {Vec2{cx - rb + shift, cy}, Vec2{cx + rb + shift, cy}, Vec2{cx + shift, cy + rb}});
    }
    const tessellate::TriangleMesh meshA = trianglesAt(camera, trianglesA);
    const tessellate::TriangleMesh meshB = trianglesAt(camera, trianglesB);
    const CoverageDistanceQuery geometryA = meshCoverageDistance(meshA, camera, kNever);
    const CoverageDistanceQuery geometryB = meshCoverageDistance(meshB, camera, kNever);
    for (bool withGeometry : {false, true}) {
      SilhouetteGeometry geometry;
      if (withGeometry) geometry = {.approximation = &geometryA, .reference = &geometryB};
      const SilhouetteMetrics nearby =
          compareSilhouettes(a, b, kS, CancelToken{}, geometry, ContourSearch::Nearby);
      const SilhouetteMetrics full =
          compareSilhouettes(a, b, kS, CancelToken{}, geometry, ContourSearch::FullTransform);
      EXPECT_EQ(nearby.hausdorffPx, full.hausdorffPx) << "trial " << trial;
      EXPECT_EQ(nearby.meanPx, full.meanPx) << "trial " << trial;
      EXPECT_EQ(nearby.iou, full.iou);
      EXPECT_EQ(nearby.mismatchPx, full.mismatchPx);
    }
  }
}

// measureGeometry evaluates each vertex once and each edge midpoint shared by two triangles
// once; the numbers must be those of evaluating all seven points of every triangle, as the
// definition reads. The oracle here does that, summing per 4096 triangles and then the chunks,
// the order measureGeometry sums in, so the two must agree exactly. Dense adaptive
// tessellations (many chunks), Catmull-Clark with triangles, n-gons and creases, and Loop.
TEST(Geometry, SharedPointsMeasuredOnceGiveTheSevenPointDefinitionExactly) {
  for (const mesh::ControlMesh& cage :
       {testing::creature(6), testing::loopCreature(5), testing::pawn(), testing::prism(7)}) {
    const subdiv::LimitSurface surface(cage);
    const Camera camera(Vec3{0.7, 1.1, 4.0}, Vec3{0, 0, 0}, Vec3{0, 1, 0}, 35,
                        Projection::Perspective, 2, 384, 384, 0.01, 100);
    tessellate::AdaptiveOptions options;
    options.dicingRate = 1.5;
    const tessellate::TriangleMesh mesh =
        tessellate::tessellateAdaptive(surface, camera, options, {});
    ASSERT_GT(mesh.triangleCount(), 3 * 4096u);
    double max = 0, sum = 0, chunkSum = 0;
    size_t count = 0;
    for (size_t t = 0; t < mesh.triangleCount(); ++t) {
      if (t % 4096 == 0) {
        sum += chunkSum;
        chunkSum = 0;
      }
      const int face = mesh.triangleFaces[t];
      if (!surface.hasLimit(face)) continue;
      const OpenSubdiv::Bfr::Parameterization param = surface.parameterization(face);
      bool oneSubFace = true;
      if (param.HasSubFaces()) {
        int sub[3];
        for (int k = 0; k < 3; ++k) {
          const float uv[2] = {mesh.cornerUVs[3 * t + k].x, mesh.cornerUVs[3 * t + k].y};
          sub[k] = param.GetSubFace(uv);
        }
        oneSubFace = sub[0] == sub[1] && sub[1] == sub[2];
      }
      for (int i = 0; i < (oneSubFace ? 7 : 3); ++i) {
        const double* w = kSevenPoints[i];
        Vec3 corner[3];
        Vec2f uv[3];
        for (int k = 0; k < 3; ++k) {
          corner[k] = mesh.positions[mesh.indices[3 * t + k]].toDouble();
          uv[k] = mesh.cornerUVs[3 * t + k];
        }
        const Vec3 onTriangle =
            i < 3 ? corner[i] : corner[0] * w[0] + corner[1] * w[1] + corner[2] * w[2];
        const double u = i < 3 ? uv[i].x : w[0] * uv[0].x + w[1] * uv[1].x + w[2] * uv[2].x;
        const double v = i < 3 ? uv[i].y : w[0] * uv[0].y + w[1] * uv[1].y + w[2] * uv[2].y;
        const double d = length(onTriangle - surface.position(face, u, v));
        max = std::max(max, d);
        chunkSum += d;
        ++count;
      }
    }
    sum += chunkSum;
    const GeometryMetrics m = measureGeometry(mesh, surface);
    EXPECT_EQ(m.maxDist, max);
    EXPECT_EQ(m.meanDist, sum / static_cast<double>(count));
  }
}

// The nearest point no triangle covers, from a point some triangle covers, by brute force: the
// coverage's edge is made of pieces of the triangles' edges, so its nearest point is the foot of
// the point on an edge, a corner, or a crossing of two edges, with uncovered points around it
// (probed 0.002 px away in 64 directions). `radius` when none is nearer.
double nearestUncoveredBruteForce(const Vec2& p, double radius,
                                  const std::vector<std::array<Vec2, 3>>& all) {
  std::vector<std::array<Vec2, 3>> near;
  for (const auto& t : all) {
    if (pointTriangleDistance(p, t[0], t[1], t[2]) < radius + 0.01) near.push_back(t);
  }
  auto covered = [&](const Vec2& q) {
    for (const auto& t : near) {
      if (pointTriangleDistance(q, t[0], t[1], t[2]) == 0) return true;
    }
    return false;
  };
  std::vector<std::pair<Vec2, Vec2>> edges;
  for (const auto& t : near) {
    for (int k = 0; k < 3; ++k) edges.push_back({t[k], t[(k + 1) % 3]});
  }
  std::vector<Vec2> candidates;
  for (const auto& [a, b] : edges) {
    candidates.push_back(a);
    const double dx = b.x - a.x, dy = b.y - a.y, length2 = dx * dx + dy * dy;
    const double u = std::clamp(((p.x - a.x) * dx + (p.y - a.y) * dy) / length2, 0.0, 1.0);
    candidates.push_back({a.x + u * dx, a.y + u * dy});
    for (const auto& [c, d] : edges) {
      const double ex = d.x - c.x, ey = d.y - c.y, den = dx * ey - dy * ex;
      if (den == 0) continue;
      const double s = ((c.x - a.x) * ey - (c.y - a.y) * ex) / den;
      const double t = ((c.x - a.x) * dy - (c.y - a.y) * dx) / den;
      if (s >= 0 && s <= 1 && t >= 0 && t <= 1) candidates.push_back({a.x + s * dx, a.y + s * dy});
    }
  }
  double best = radius;
  for (const Vec2& c : candidates) {
    const double d = std::hypot(c.x - p.x, c.y - p.y);
    if (d >= best) continue;
    for (int k = 0; k < 64; ++k) {
      const double angle = 2 * M_PI * k / 64;
      if (!covered({c.x + 0.002 * std::cos(angle), c.y + 0.002 * std::sin(angle)})) {
        best = d;
        break;
      }
    }
  }
  return best;
}

// The query visits only the triangles filed near each batch's points; its distances must be
// those of measuring every triangle: small triangles, large ones (listed apart), points near
// bucket borders and off the image, bounds small and large. Points the triangles cover are
// measured to the nearest point they leave uncovered (within kMaxGapSearchPx = 8 px), which a
// brute force finds.
TEST(CoverageDistance, MatchesEveryTriangleOnRandomMeshes) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const Camera camera = pixelCamera(256, 256);
  std::vector<std::array<Vec2, 3>> triangles;
  for (int t = 0; t < 3000; ++t) {
    const double size = t % 100 == 0 ? 150 : 12;
    const Vec2 a{unit(rng) * 300 - 20, unit(rng) * 300 - 20};
    triangles.push_back({a, Vec2{a.x + size * unit(rng), a.y + size * unit(rng)},
                         Vec2{a.x - size * unit(rng), a.y + size * unit(rng)}});
  }
  const tessellate::TriangleMesh mesh = trianglesAt(camera, triangles);
  std::vector<Vec2> corners(mesh.positions.size());
  for (size_t v = 0; v < corners.size(); ++v) {
    const Vec3 p = camera.project(mesh.positions[v].toDouble());
    corners[v] = {p.x, p.y};
  }
  std::vector<Vec2> points;
  std::vector<double> bounds;
  for (int k = 0; k < 600; ++k) {
    points.push_back({unit(rng) * 280 - 12, unit(rng) * 280 - 12});
    bounds.push_back(k % 3 == 0 ? 60 * unit(rng) : 4 * unit(rng));
  }
  std::vector<double> expected = bounds;
  size_t gapsNearer = 0;  // covered points with uncovered ones nearer than their bounds
  for (size_t k = 0; k < points.size(); ++k) {
    double nearest = bounds[k];
    bool covered = false;
    for (size_t t = 0; t < triangles.size(); ++t) {
      const double d =
          pointTriangleDistance(points[k], corners[3 * t], corners[3 * t + 1], corners[3 * t + 2]);
      covered = covered || d == 0;
      nearest = std::min(nearest, d);
    }
    if (!covered) {
      expected[k] = nearest;
    } else {
      const double radius = std::min(bounds[k], 8.0);
      const double gap = nearestUncoveredBruteForce(points[k], radius, triangles);
      if (gap < radius) expected[k] = gap;
      gapsNearer += gap < radius;
    }
  }
  const CoverageDistanceQuery query = meshCoverageDistance(mesh, camera, kNever);
  std::vector<double> measured = bounds;
  query(points, measured);
  // The gaps are searched a thousandth of a pixel off the triangles' edges, the brute force
  // probes at two thousandths: the two agree within those.
  for (size_t k = 0; k < points.size(); ++k) EXPECT_NEAR(measured[k], expected[k], 0.004) << k;
  std::printf("%zu covered points have uncovered ones nearer than their bounds\n", gapsNearer);
  EXPECT_GT(gapsNearer, 20u);
  // Batches of a few points, as lowerLargestFirst sends them: the same answers.
  for (size_t k = 0; k < points.size(); k += 7) {
    std::vector<Vec2> few(points.begin() + k, points.begin() + std::min(points.size(), k + 7));
    std::vector<double> fewBounds(bounds.begin() + k,
                                  bounds.begin() + std::min(points.size(), k + 7));
    query(few, fewBounds);
    for (size_t i = 0; i < few.size(); ++i) EXPECT_EQ(fewBounds[i], measured[k + i]) << k + i;
  }
}

}  // namespace
}  // namespace limn::render::metrics
