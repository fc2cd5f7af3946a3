// Tests of render/normalmap: the exact nearest-feature transform against brute force, the
// normal atlas against LimitSurface::evaluate (texels, bilinear samples, dilation, layout,
// limits), and the mapped cage drawn with Shading::NormalMap against the limit normals of the
// points it shows.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "render/core/error.h"
#include "render/normalmap/mapped_cage.h"
#include "render/normalmap/nearest_feature.h"
#include "render/normalmap/normal_atlas.h"
#include "render/raster/rasterizer.h"
#include "render/tessellate/tessellate.h"
#include "tests/support/corpus.h"
#include "tests/unit/test_meshes.h"

namespace limn::render::normalmap {
namespace {

using mesh::ControlMesh;
using OpenSubdiv::Bfr::Parameterization;
using subdiv::LimitSurface;
using tessellate::TriangleMesh;

// ---- Helpers ----

Vec3 texel(const Image& image, int x, int y) {
  return {image.at(x, y, 0), image.at(x, y, 1), image.at(x, y, 2)};
}

// What GL_LINEAR with clamp-to-edge reads at atlas coordinate c, renormalised.
Vec3 bilinear(const Image& image, Vec2f c) {
  const double x = c.x * image.width - 0.5, y = c.y * image.height - 0.5;
  const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
  const double fx = x - x0, fy = y - y0;
  auto at = [&](int i, int j) {
    return texel(image, std::clamp(i, 0, image.width - 1), std::clamp(j, 0, image.height - 1));
  };
  return normalize((at(x0, y0) * (1 - fx) + at(x0 + 1, y0) * fx) * (1 - fy) +
                   (at(x0, y0 + 1) * (1 - fx) + at(x0 + 1, y0 + 1) * fx) * fy);
}

double angleDeg(const Vec3& a, const Vec3& b) {
  return std::acos(std::clamp(dot(normalize(a), normalize(b)), -1.0, 1.0)) * 180.0 /
         std::numbers::pi;
}

// A face parameter (u, v) drawn uniformly from the face's domain: [0,1]^2 for quads, u + v <= 1
// for triangles, a random sub-face's normalised square otherwise.
Vec2 randomParameter(const LimitSurface& surface, int face, std::mt19937& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const Parameterization p = surface.parameterization(face);
  double u = unit(rng), v = unit(rng);
  if (p.GetType() == Parameterization::TRI && u + v > 1) {
    u = 1 - u;
    v = 1 - v;
  }
  if (!p.HasSubFaces()) return {u, v};
  const double st[2] = {u, v};
  double uv[2];
  p.ConvertNormalizedSubFaceToCoord(static_cast<int>(rng() % p.GetFaceSize()), st, uv);
  return {uv[0], uv[1]};
}

struct Shape {
  std::string name;
  ControlMesh mesh;
};

// Code-made shapes (every Bfr parameterisation kind) and corpus shapes where present.
std::vector<Shape> shapes() {
  std::vector<Shape> out = {
      {"cube (Catmull-Clark quads)", testing::cube()},
      {"octahedron (Catmull-Clark triangles: sub-faces)", testing::octahedron()},
      {"icosahedron (Loop)", testing::icosahedron()},
      {"torus 12x8 with creases", testing::torus()},
  };
  for (const char* name : {"catmark_nonquads", "catmark_hole_test1", "catmark_xord_interior",
                           "loop_xord_interior", "bilinear_cube", "catmark_edgenone"}) {
    if (auto m = testing::readCorpusShape(name)) out.push_back({name, *m});
  }
  return out;
}

// ---- Nearest-feature transform ----

TEST(NearestFeature, MatchesBruteForce) {
  std::mt19937 rng(7);
  for (auto [width, height, density] :
       {std::tuple{37, 23, 0.05}, std::tuple{64, 64, 0.002}, std::tuple{1, 40, 0.1},
        std::tuple{50, 1, 0.1}, std::tuple{90, 70, 0.3}}) {
    std::vector<uint8_t> feature(static_cast<size_t>(width) * height, 0);
    std::bernoulli_distribution pick(density);
    for (auto& f : feature) f = pick(rng);
    feature[rng() % feature.size()] = 1;  // at least one
    const std::vector<int64_t> nearest = nearestFeature(feature, width, height);
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) {
        int64_t best = INT64_MAX;
        for (int v = 0; v < height; ++v)
          for (int u = 0; u < width; ++u)
            if (feature[static_cast<size_t>(v) * width + u])
              best = std::min<int64_t>(best, (u - x) * (u - x) + (v - y) * (v - y));
        const int64_t found = nearest[static_cast<size_t>(y) * width + x];
        ASSERT_GE(found, 0);
        ASSERT_TRUE(feature[found]) << x << ", " << y;
        const int64_t fx = found % width, fy = found / width;
        ASSERT_EQ((fx - x) * (fx - x) + (fy - y) * (fy - y), best) << x << ", " << y;
      }
    }
  }
}

TEST(NearestFeature, NoFeatureAndAllFeatures) {
  std::vector<int64_t> none = nearestFeature(std::vector<uint8_t>(12, 0), 4, 3);
  for (int64_t i : none) EXPECT_EQ(i, -1);
  std::vector<int64_t> all = nearestFeature(std::vector<uint8_t>(12, 1), 4, 3);
  for (size_t i = 0; i < all.size(); ++i) EXPECT_EQ(all[i], static_cast<int64_t>(i));
  EXPECT_THROW(nearestFeature(std::vector<uint8_t>(11, 1), 4, 3), std::invalid_argument);
}

// ---- The atlas ----

TEST(NormalAtlas, TexelsHoldTheLimitNormalAtTheirParameter) {
  for (const Shape& shape : shapes()) {
    SCOPED_TRACE(shape.name);
    LimitSurface surface(shape.mesh);
    const int n = 10;  // texels 0, 3, 6, 9: (u, v) = 1/3 and 2/3 are texel centres
    NormalAtlas atlas(surface, n);
    const Image& image = *atlas.image();
    int checked = 0;
    for (int f = 0; f < surface.faceCount(); ++f) {
      ASSERT_EQ(atlas.hasChart(f), surface.hasLimit(f)) << "face " << f;
      if (!atlas.hasChart(f)) continue;
      const Parameterization p = surface.parameterization(f);
      const int subFaces = p.HasSubFaces() ? p.GetFaceSize() : 1;
      for (int s = 0; s < subFaces; ++s) {
        for (int j = 0; j < n; ++j) {
          for (int i = 0; i < n; ++i) {
            if (p.GetType() == Parameterization::TRI && i + j > n - 1) continue;
            const Vec2 st{static_cast<double>(i) / (n - 1), static_cast<double>(j) / (n - 1)};
            double uv[2] = {st.x, st.y};
            if (p.HasSubFaces()) {
              const double in[2] = {st.x, st.y};
              p.ConvertNormalizedSubFaceToCoord(s, in, uv);
            }
            // The coordinate lands on a texel centre (this also covers the chart centres).
            const Vec2f c = p.HasSubFaces() ? atlas.subFaceCoordinate(f, s, st)
                                            : atlas.coordinate(f, {uv[0], uv[1]});
            const double x = c.x * image.width - 0.5, y = c.y * image.height - 0.5;
            ASSERT_NEAR(x, std::round(x), 1e-3);
            ASSERT_NEAR(y, std::round(y), 1e-3);
            const Vec3 expected = surface.evaluate(f, uv[0], uv[1]).normal;
            const Vec3 got =
                texel(image, static_cast<int>(std::lround(x)), static_cast<int>(std::lround(y)));
            ASSERT_LT(length(got - expected), 1e-6) << "face " << f << " texel " << i << ", " << j;
            ++checked;
          }
        }
      }
    }
    EXPECT_GT(checked, 0);
  }
}

TEST(NormalAtlas, BilinearSamplesFollowTheLimitNormal) {
  std::mt19937 rng(11);
  for (const Shape& shape : shapes()) {
    LimitSurface surface(shape.mesh);
    for (int n : {16, 64}) {
      NormalAtlas atlas(surface, n);
      double worst = 0, worstAwayFromCorners = 0, sum = 0;
      int samples = 0;
      for (int f = 0; f < surface.faceCount(); ++f) {
        if (!atlas.hasChart(f)) continue;
        const int corners = surface.parameterization(f).GetFaceSize();
        for (int k = 0; k < 200; ++k) {
          const Vec2 uv = randomParameter(surface, f, rng);
          const double error = angleDeg(bilinear(*atlas.image(), atlas.coordinate(f, uv)),
                                        surface.evaluate(f, uv.x, uv.y).normal);
          worst = std::max(worst, error);
          sum += error;
          ++samples;
          // Near an extraordinary vertex the normal is not smooth in (u, v) (it turns like a
          // fractional power of the distance), so the first texels there are less exact.
          bool nearCorner = false;
          for (int c = 0; c < corners; ++c) {
            const Vec2 corner = surface.cornerUV(f, c);
            nearCorner = nearCorner || std::hypot(uv.x - corner.x, uv.y - corner.y) < 2.0 / (n - 1);
          }
          if (!nearCorner) worstAwayFromCorners = std::max(worstAwayFromCorners, error);
        }
      }
      std::printf(
          "[ atlas    ] %-48s %2d texels: bilinear vs limit normal: mean %.3f deg, "
          "max %.3f deg (%.3f deg 2 texels from the corners)\n",
          shape.name.c_str(), n, sum / samples, worst, worstAwayFromCorners);
      // Fine charts are within a degree but for the first texels at extraordinary vertices.
      if (n == 64) {
        EXPECT_LT(worstAwayFromCorners, 1.0) << shape.name;
        EXPECT_LT(worst, 5.0) << shape.name;
        EXPECT_LT(sum / samples, 0.05) << shape.name;
      }
    }
  }
}

TEST(NormalAtlas, EveryTexelIsAUnitNormal) {
  for (const Shape& shape : shapes()) {
    LimitSurface surface(shape.mesh);
    for (int n : {4, 7, 16}) {
      NormalAtlas atlas(surface, n);
      const Image& image = *atlas.image();
      ASSERT_EQ(image.channels, 3);
      for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x)
          ASSERT_NEAR(length(texel(image, x, y)), 1.0, 1e-5)
              << shape.name << ", " << n << " texels: texel " << x << ", " << y;
    }
  }
}

TEST(NormalAtlas, DilationCopiesTheNearestTexelInside) {
  // Loop triangles: texel (i, j) with i + j > n - 1 is outside the face's domain and takes the
  // value of its nearest texel inside. For the two rows of texels beyond the hypotenuse
  // i + j = n - 1 (those bilinear sampling reads) that lies on the hypotenuse; farther ones may
  // be nearer to the next chart.
  LimitSurface surface(testing::icosahedron());
  const int n = 8;
  NormalAtlas atlas(surface, n);
  const Image& image = *atlas.image();
  const Vec2f origin = atlas.coordinate(5, {0, 0});
  const int x0 = static_cast<int>(origin.x * image.width),
            y0 = static_cast<int>(origin.y * image.height);
  for (int j = 0; j < n; ++j) {
    for (int i = n - j; i < n && i + j <= n + 1; ++i) {
      // The nearest texels on the hypotenuse: where the diagonal through (i, j) meets it.
      const int excess = i + j - (n - 1);
      bool matches = false;
      for (int a : {excess / 2, (excess + 1) / 2}) {
        const int bi = i - a, bj = j - (excess - a);
        matches =
            matches || length(texel(image, x0 + i, y0 + j) - texel(image, x0 + bi, y0 + bj)) < 1e-7;
      }
      EXPECT_TRUE(matches) << i << ", " << j;
    }
  }
}

TEST(NormalAtlas, LayoutAndLimits) {
  LimitSurface surface(testing::torus(12, 8));  // 96 quads: a 10 x 10 grid of charts
  NormalAtlas atlas(surface, 16);
  EXPECT_EQ(atlas.chartCount(), 96);
  EXPECT_EQ(NormalAtlas::chartCountOf(surface), 96);
  EXPECT_EQ(atlas.width(), 10 * 16 + 9 * NormalAtlas::kGutter);
  EXPECT_EQ(atlas.height(), atlas.width());
  EXPECT_EQ(atlas.chartTexels(), 16);
  // Charts do not overlap: every chart's texel-centre box is apart from every other's.
  std::vector<std::array<double, 4>> boxes;
  for (int f = 0; f < surface.faceCount(); ++f) {
    Vec2f a = atlas.coordinate(f, {0, 0}), b = atlas.coordinate(f, {1, 1});
    boxes.push_back(
        {a.x * atlas.width(), a.y * atlas.height(), b.x * atlas.width(), b.y * atlas.height()});
    EXPECT_NEAR(boxes.back()[2] - boxes.back()[0], 15.0, 1e-3);
    EXPECT_GE(std::min(a.x, a.y), 0.0f);
    EXPECT_LE(std::max(b.x, b.y), 1.0f);
  }
  for (size_t i = 0; i < boxes.size(); ++i)
    for (size_t k = i + 1; k < boxes.size(); ++k) {
      const bool apart = boxes[i][2] + 1 < boxes[k][0] || boxes[k][2] + 1 < boxes[i][0] ||
                         boxes[i][3] + 1 < boxes[k][1] || boxes[k][3] + 1 < boxes[i][1];
      ASSERT_TRUE(apart) << i << " and " << k;
    }

  try {
    NormalAtlas tooBig(surface, 64, 500);
    FAIL() << "no LimitExceeded";
  } catch (const InputError& e) {
    EXPECT_EQ(e.kind(), InputError::Kind::LimitExceeded);
    EXPECT_EQ(e.subject(), "maxAtlasSide");
  }
  EXPECT_NO_THROW(NormalAtlas(surface, 64, NormalAtlas::sideFor(96, 64)));
  EXPECT_THROW(NormalAtlas(surface, 3), std::invalid_argument);
  EXPECT_THROW(atlas.coordinate(96, {0, 0}), std::invalid_argument);
  EXPECT_THROW(atlas.subFaceCoordinate(0, 1, {0, 0}), std::invalid_argument);
}

TEST(NormalAtlas, HolesGetNoChart) {
  ControlMesh m = testing::torus(12, 8);
  m.holes = {3, 40};
  LimitSurface surface(m);
  NormalAtlas atlas(surface, 8);
  EXPECT_EQ(atlas.chartCount(), 94);
  EXPECT_FALSE(atlas.hasChart(3));
  EXPECT_FALSE(atlas.hasChart(40));
  EXPECT_TRUE(atlas.hasChart(4));
  EXPECT_THROW(atlas.coordinate(3, {0.5, 0.5}), std::invalid_argument);
  // All holes: one texel, still a unit normal.
  ControlMesh cube = testing::cube();
  cube.holes = {0, 1, 2, 3, 4, 5};
  LimitSurface none(cube);
  NormalAtlas empty(none, 8);
  EXPECT_EQ(empty.chartCount(), 0);
  EXPECT_EQ(empty.width() * empty.height(), 1);
  EXPECT_NEAR(length(texel(*empty.image(), 0, 0)), 1.0, 1e-6);
}

TEST(NormalAtlas, ChartSizeHelpers) {
  LimitSurface surface(testing::torus(40, 25));  // 1000 charts
  const int n = chartTexelsForBudget(surface, 4'000'000, 8192);
  // 1000 charts of (n + 1)^2 texels within 4M: n + 1 <= 63.
  EXPECT_EQ(n, 62);
  EXPECT_EQ(chartTexelsForBudget(surface, 4'000'000, 1000), 30);  // 32 columns of 31 - 1
  EXPECT_EQ(chartTexelsForBudget(surface, 10, 8192), NormalAtlas::kMinChartTexels);
  EXPECT_LE(NormalAtlas::sideFor(1000, chartTexelsForBudget(surface, 1u << 30, 2048, 1000)), 2048);

  // The camera: the largest face seen from near is larger on screen, so it asks for more.
  const Camera farCamera({0, 0, 8}, {0, 0, 0}, {0, 1, 0}, 40.0, Projection::Perspective, 2.0, 512,
                         512, 0.1, 100.0);
  const Camera nearCamera({0, 0, 2}, {0, 0, 0}, {0, 1, 0}, 40.0, Projection::Perspective, 2.0, 512,
                          512, 0.1, 100.0);
  const int farTexels = chartTexelsForCamera(surface, farCamera, 1.0, 1u << 30, 8192);
  const int nearTexels = chartTexelsForCamera(surface, nearCamera, 1.0, 1u << 30, 8192);
  EXPECT_GT(nearTexels, farTexels);
  EXPECT_GE(farTexels, NormalAtlas::kMinChartTexels);
  EXPECT_EQ(chartTexelsForCamera(surface, nearCamera, 100.0, 4'000'000, 8192), 62);
  std::printf("[ atlas    ] torus 40x25 at 512 px: %d texels per chart from 8 units, %d from 2\n",
              farTexels, nearTexels);
}

TEST(NormalAtlas, SubFaceCornersMeetAtEdgeMidpoints) {
  // mappedCage relies on it: sub-face k's (1, 0) is the midpoint of edge k and its (0, 1) that
  // of edge k - 1, so (1, 0) of sub-face k is (0, 1) of sub-face k + 1 on the surface.
  for (const ControlMesh& m :
       {testing::octahedron(),
        testing::readCorpusShape("catmark_nonquads").value_or(testing::octahedron())}) {
    LimitSurface surface(m);
    for (int f = 0; f < surface.faceCount(); ++f) {
      const Parameterization p = surface.parameterization(f);
      if (!surface.hasLimit(f) || !p.HasSubFaces()) continue;
      const int n = p.GetFaceSize();
      for (int k = 0; k < n; ++k) {
        const double a[2] = {1, 0}, b[2] = {0, 1}, corner[2] = {0, 0};
        double ua[2], ub[2], uc[2];
        p.ConvertNormalizedSubFaceToCoord(k, a, ua);
        p.ConvertNormalizedSubFaceToCoord((k + 1) % n, b, ub);
        p.ConvertNormalizedSubFaceToCoord(k, corner, uc);
        EXPECT_LT(length(surface.position(f, ua[0], ua[1]) - surface.position(f, ub[0], ub[1])),
                  1e-9);
        const Vec2 cornerUV = surface.cornerUV(f, k);
        EXPECT_NEAR(uc[0], cornerUV.x, 1e-12);
        EXPECT_NEAR(uc[1], cornerUV.y, 1e-12);
      }
    }
  }
}

TEST(NormalAtlas, BuildTimes) {
  // Not an assertion: the cost of baking, for the report (2-core CPU shared with others).
  LimitSurface surface(testing::torus(40, 25));
  for (int n : {16, 32, 64}) {
    const auto start = std::chrono::steady_clock::now();
    NormalAtlas atlas(surface, n);
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    // The dilation's share: the nearest-feature transform of a mask like the atlas's.
    std::vector<uint8_t> inside(static_cast<size_t>(atlas.width()) * atlas.height(), 0);
    const int pitch = n + NormalAtlas::kGutter;
    for (int y = 0; y < atlas.height(); ++y) {
      for (int x = 0; x < atlas.width(); ++x) {
        inside[static_cast<size_t>(y) * atlas.width() + x] = x % pitch < n && y % pitch < n;
      }
    }
    const auto edtStart = std::chrono::steady_clock::now();
    const std::vector<int64_t> nearest = nearestFeature(inside, atlas.width(), atlas.height());
    const double edtMs =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - edtStart)
            .count();
    std::printf(
        "[ atlas    ] torus 40x25 (%d faces), %2d texels per chart: %d x %d atlas, "
        "%.1f ms (nearest-feature transform alone: %.1f ms)\n",
        surface.faceCount(), n, atlas.width(), atlas.height(), ms, edtMs);
    EXPECT_EQ(nearest.size(), inside.size());
  }
}

// ---- The mapped cage ----

TEST(MappedCage, EveryTriangleStaysInOneChart) {
  for (const Shape& shape : shapes()) {
    SCOPED_TRACE(shape.name);
    LimitSurface surface(shape.mesh);
    NormalAtlas atlas(surface, 8);
    const TriangleMesh mesh = mappedCage(surface, atlas);
    ASSERT_EQ(mesh.texcoords.size(), mesh.positions.size());
    ASSERT_EQ(mesh.normals.size(), mesh.positions.size());
    ASSERT_EQ(mesh.limitPositions.size(), mesh.positions.size());
    ASSERT_EQ(mesh.normalMap, atlas.image());
    ASSERT_GT(mesh.triangleCount(), 0u);
    ASSERT_EQ(mesh.lines.size() % 2, 0u);
    const double pitch = atlas.chartTexels() + NormalAtlas::kGutter;
    for (size_t t = 0; t < mesh.triangleCount(); ++t) {
      int chartX = -1, chartY = -1;
      for (int k = 0; k < 3; ++k) {
        const Vec2f c = mesh.texcoords[mesh.indices[3 * t + k]];
        ASSERT_TRUE(c.x >= 0 && c.x <= 1 && c.y >= 0 && c.y <= 1);
        const int cx = static_cast<int>(c.x * atlas.width() / pitch);
        const int cy = static_cast<int>(c.y * atlas.height() / pitch);
        if (k > 0) {
          ASSERT_EQ(cx, chartX) << "triangle " << t;
          ASSERT_EQ(cy, chartY) << "triangle " << t;
        }
        chartX = cx;
        chartY = cy;
      }
    }
  }
}

// A ray-triangle hit (Moller-Trumbore): distance along the ray and barycentrics of b and c.
bool intersect(const Ray& ray, const Vec3& a, const Vec3& b, const Vec3& c, double& t, double& beta,
               double& gamma) {
  const Vec3 e1 = b - a, e2 = c - a;
  const Vec3 p = cross(ray.direction, e2);
  const double det = dot(e1, p);
  if (std::fabs(det) < 1e-14) return false;
  const Vec3 s = ray.origin - a;
  beta = dot(s, p) / det;
  const Vec3 q = cross(s, e1);
  gamma = dot(ray.direction, q) / det;
  t = dot(e2, q) / det;
  return beta >= 0 && gamma >= 0 && beta + gamma <= 1 && t > 0;
}

// Mean angle, over the pixels where the normal pass shows the mapped cage and the pixel centre
// is at least 1 px inside one of its triangles, between the pass and the limit normal of the
// point of the limit surface that the pixel shows: the parameter interpolated over the
// triangle, as the texture coordinates are. `meshParameters` gives each vertex's face and
// (u, v).
struct NormalErrors {
  double mapped = 0, smooth = 0, flat = 0;
  int pixels = 0;
};

NormalErrors measureNormals(const LimitSurface& surface, const TriangleMesh& mesh,
                            const std::vector<int>& vertexFace, const std::vector<Vec2>& vertexUV,
                            const Camera& camera, raster::Rasterizer& rasterizer) {
  PassSelection passes;
  passes.normal = passes.mask = true;
  const Image mapped =
      rasterizer.render(mesh, camera, passes, Shading::NormalMap).passes.at(pass::kNormal);
  const Image smooth =
      rasterizer.render(mesh, camera, passes, Shading::Smooth).passes.at(pass::kNormal);
  const Image flat =
      rasterizer.render(mesh, camera, passes, Shading::Flat).passes.at(pass::kNormal);
  NormalErrors errors;
  for (int y = 0; y < camera.height(); ++y) {
    for (int x = 0; x < camera.width(); ++x) {
      const Ray ray = camera.rayThrough(x + 0.5, y + 0.5);
      double best = 1e300, bestBeta = 0, bestGamma = 0;
      size_t bestTriangle = 0;
      for (size_t t = 0; t < mesh.triangleCount(); ++t) {
        const uint32_t* v = &mesh.indices[3 * t];
        double d, beta, gamma;
        if (intersect(ray, mesh.positions[v[0]].toDouble(), mesh.positions[v[1]].toDouble(),
                      mesh.positions[v[2]].toDouble(), d, beta, gamma) &&
            d < best) {
          best = d;
          bestBeta = beta;
          bestGamma = gamma;
          bestTriangle = t;
        }
      }
      if (best == 1e300) continue;
      // At least about a pixel inside the triangle on screen: barycentrics well away from 0.
      const uint32_t* v = &mesh.indices[3 * bestTriangle];
      Vec3 p[3];
      for (int k = 0; k < 3; ++k) p[k] = camera.project(mesh.positions[v[k]].toDouble());
      const double area =
          std::fabs((p[1].x - p[0].x) * (p[2].y - p[0].y) - (p[2].x - p[0].x) * (p[1].y - p[0].y));
      const double margin = 1.5 *
                            std::max({std::hypot(p[1].x - p[0].x, p[1].y - p[0].y),
                                      std::hypot(p[2].x - p[1].x, p[2].y - p[1].y),
                                      std::hypot(p[0].x - p[2].x, p[0].y - p[2].y)}) /
                            area;
      const double alpha = 1 - bestBeta - bestGamma;
      if (std::min({alpha, bestBeta, bestGamma}) < margin) continue;
      const int face = vertexFace[v[0]];
      const double u =
          alpha * vertexUV[v[0]].x + bestBeta * vertexUV[v[1]].x + bestGamma * vertexUV[v[2]].x;
      const double w =
          alpha * vertexUV[v[0]].y + bestBeta * vertexUV[v[1]].y + bestGamma * vertexUV[v[2]].y;
      const Vec3 limit = surface.evaluate(face, u, w).normal;
      auto at = [&](const Image& image) { return texel(image, x, y); };
      errors.mapped += angleDeg(at(mapped), limit);
      errors.smooth += angleDeg(at(smooth), limit);
      errors.flat += angleDeg(at(flat), limit);
      ++errors.pixels;
    }
  }
  if (errors.pixels > 0) {
    errors.mapped /= errors.pixels;
    errors.smooth /= errors.pixels;
    errors.flat /= errors.pixels;
  }
  return errors;
}

TEST(MappedCage, NormalMapShadingShowsTheLimitNormals) {
  raster::Rasterizer rasterizer;
  for (const Shape& shape : {Shape{"cube (Catmull-Clark)", testing::cube()},
                             Shape{"octahedron (Catmull-Clark sub-faces)", testing::octahedron()},
                             Shape{"icosahedron (Loop)", testing::icosahedron()}}) {
    LimitSurface surface(shape.mesh);
    NormalAtlas atlas(surface, 32);
    const TriangleMesh mesh = mappedCage(surface, atlas);
    // Each vertex's face and parameter, recovered as mappedCage makes them (the same order).
    std::vector<int> vertexFace;
    std::vector<Vec2> vertexUV;
    for (int f = 0; f < surface.faceCount(); ++f) {
      const Parameterization p = surface.parameterization(f);
      if (!p.HasSubFaces()) {
        for (int k = 0; k < p.GetFaceSize(); ++k) {
          vertexFace.push_back(f);
          vertexUV.push_back(surface.cornerUV(f, k));
        }
        continue;
      }
      for (int k = 0; k < p.GetFaceSize(); ++k) {
        for (const auto& st : {std::array<double, 2>{0, 0}, {1, 0}, {1, 1}, {0, 1}}) {
          double uv[2];
          p.ConvertNormalizedSubFaceToCoord(k, st.data(), uv);
          vertexFace.push_back(f);
          vertexUV.push_back({uv[0], uv[1]});
        }
      }
    }
    ASSERT_EQ(vertexFace.size(), mesh.positions.size());
    // The texture coordinates are where the atlas puts those parameters.
    for (size_t i = 0; i < vertexFace.size(); ++i) {
      const Vec2f c = atlas.coordinate(vertexFace[i], vertexUV[i]);
      ASSERT_NEAR(c.x, mesh.texcoords[i].x, 1e-6);
      ASSERT_NEAR(c.y, mesh.texcoords[i].y, 1e-6);
    }
    const Bounds bounds = surface.bounds();
    const double r = bounds.diagonal();
    const Camera camera(bounds.center() + Vec3{0.8, 0.6, 1.4} * r, bounds.center(), {0, 1, 0}, 35.0,
                        Projection::Perspective, 2.0, 256, 224, 0.1 * r, 10 * r);
    const NormalErrors e = measureNormals(surface, mesh, vertexFace, vertexUV, camera, rasterizer);
    std::printf(
        "[ mapped   ] %-40s mean angle to the limit normal over %d px: normal map %.3f "
        "deg, smooth %.2f deg, flat %.2f deg\n",
        shape.name.c_str(), e.pixels, e.mapped, e.smooth, e.flat);
    EXPECT_GT(e.pixels, 1500);
    EXPECT_LT(e.mapped, 0.5);
    EXPECT_GT(e.flat, 10 * e.mapped + 3.0);
    EXPECT_GT(e.smooth, 2 * e.mapped);
  }
}

}  // namespace
}  // namespace limn::render::normalmap
