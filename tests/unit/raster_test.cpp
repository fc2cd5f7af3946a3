// Tests of render/raster: the headless EGL/OpenGL rasteriser against what the camera and the
// shading model say each pixel must hold (coverage from Camera::project, linear depth, normals,
// shading::shade colours, supersampled coverage, tiles, wireframe, line overlays, normal maps,
// threads).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <memory>
#include <numbers>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "render/core/camera.h"
#include "render/core/overlay.h"
#include "render/core/shading.h"
#include "render/raster/rasterizer.h"
#include "render/raster/shaders.h"
#include "render/raster/tiling.h"

namespace limn::render::raster {
namespace {

using tessellate::TriangleMesh;

// A planar quad a, b, c, d (counter-clockwise seen from where `normal` points) as two
// triangles, every vertex carrying that normal.
TriangleMesh quad(Vec3 a, Vec3 b, Vec3 c, Vec3 d) {
  TriangleMesh mesh;
  Vec3f n(normalize(cross(b - a, d - a)));
  for (const Vec3& p : {a, b, c, d}) {
    mesh.positions.emplace_back(p);
    mesh.normals.push_back(n);
  }
  mesh.indices = {0, 1, 2, 0, 2, 3};
  return mesh;
}

TriangleMesh append(TriangleMesh a, const TriangleMesh& b) {
  const uint32_t base = static_cast<uint32_t>(a.positions.size());
  a.positions.insert(a.positions.end(), b.positions.begin(), b.positions.end());
  a.normals.insert(a.normals.end(), b.normals.begin(), b.normals.end());
  for (uint32_t i : b.indices) a.indices.push_back(base + i);
  return a;
}

// The quad of most tests: off-centre and tilted, so flips and offsets of rows, columns or
// depth would show. Its corners, counter-clockwise seen from +Z.
const Vec3 kQuad[4] = {{-1.3, -0.4, 0.3}, {0.7, -0.4, -0.2}, {0.7, 1.1, -0.2}, {-1.3, 1.1, 0.3}};
TriangleMesh tiltedQuad() { return quad(kQuad[0], kQuad[1], kQuad[2], kQuad[3]); }
Vec3 tiltedQuadNormal() { return normalize(cross(kQuad[1] - kQuad[0], kQuad[3] - kQuad[0])); }

Camera perspectiveCamera(int width = 64, int height = 48) {
  return Camera({0.4, 0.3, 5}, {0, 0.2, 0}, {0, 1, 0}, 35.0, Projection::Perspective, 2.0, width,
                height, 1.0, 10.0);
}

Camera orthographicCamera(int width = 64, int height = 48) {
  return Camera({0.4, 0.3, 5}, {0, 0.2, 0}, {0, 1, 0}, 35.0, Projection::Orthographic, 3.0, width,
                height, 1.0, 10.0);
}

// Where the pixel centre (x, y) of `camera` meets the plane of the tilted quad, if it does.
bool hitQuadPlane(const Camera& camera, double x, double y, Vec3& hit) {
  Ray ray = camera.rayThrough(x, y);
  Vec3 n = tiltedQuadNormal();
  double denom = dot(ray.direction, n);
  if (std::fabs(denom) < 1e-12) return false;
  double t = dot(kQuad[0] - ray.origin, n) / denom;
  hit = ray.origin + ray.direction * t;
  return t > 0;
}

// Signed distance in pixels from (x, y) to the inside of a convex polygon projected by
// `camera` (positive inside): the coverage the rasteriser must produce, from Camera::project.
double insideDistance(const Camera& camera, const std::vector<Vec3>& polygon, double x, double y) {
  std::vector<Vec3> px;
  for (const Vec3& p : polygon) px.push_back(camera.project(p));
  // Orientation of the projected polygon (pixel y points down).
  double area = 0;
  for (size_t i = 0; i < px.size(); ++i) {
    const Vec3& a = px[i];
    const Vec3& b = px[(i + 1) % px.size()];
    area += a.x * b.y - b.x * a.y;
  }
  double sign = area > 0 ? 1.0 : -1.0;
  double distance = 1e300;
  for (size_t i = 0; i < px.size(); ++i) {
    const Vec3& a = px[i];
    const Vec3& b = px[(i + 1) % px.size()];
    double ex = b.x - a.x, ey = b.y - a.y;
    double cross2 = ex * (y - a.y) - ey * (x - a.x);
    distance = std::min(distance, sign * cross2 / std::hypot(ex, ey));
  }
  return distance;
}

std::vector<Vec3> quadCorners() { return {kQuad[0], kQuad[1], kQuad[2], kQuad[3]}; }

// Distance from point (x, y) to the segment a-b, in pixels.
double segmentDistance(Vec3 a, Vec3 b, double x, double y) {
  double ex = b.x - a.x, ey = b.y - a.y;
  double t = std::clamp(((x - a.x) * ex + (y - a.y) * ey) / (ex * ex + ey * ey), 0.0, 1.0);
  return std::hypot(x - (a.x + t * ex), y - (a.y + t * ey));
}

PassSelection allPasses(int supersample = 0) {
  PassSelection passes;
  passes.color = passes.mask = passes.depth = passes.normal = true;
  passes.supersample = supersample;
  return passes;
}

class RasterTest : public ::testing::Test {
 protected:
  // One context for the whole suite: creating one costs tens of milliseconds.
  static void SetUpTestSuite() { rasterizer_ = new Rasterizer(); }
  static void TearDownTestSuite() {
    delete rasterizer_;
    rasterizer_ = nullptr;
  }
  static Rasterizer& rasterizer() { return *rasterizer_; }

  // Checks mask, depth, normal and colour of the tilted quad against the camera, pixel by
  // pixel, skipping pixel centres within 1e-3 px of its outline.
  static void expectTiltedQuad(const ImageSet& images, const Camera& camera) {
    const Image* mask = images.find(pass::kMask);
    const Image* depth = images.find(pass::kDepth);
    const Image* normal = images.find(pass::kNormal);
    const Image* color = images.find(pass::kColor);
    ASSERT_TRUE(mask && depth && normal && color);
    ASSERT_EQ(mask->width, camera.width());
    ASSERT_EQ(mask->height, camera.height());
    ASSERT_EQ(depth->channels, 1);
    ASSERT_EQ(normal->channels, 3);
    ASSERT_EQ(color->channels, 4);
    const Vec3 n = tiltedQuadNormal();
    int covered = 0, checked = 0;
    for (int y = 0; y < camera.height(); ++y) {
      for (int x = 0; x < camera.width(); ++x) {
        double inside = insideDistance(camera, quadCorners(), x + 0.5, y + 0.5);
        if (std::fabs(inside) < 1e-3) continue;
        ++checked;
        const bool expected = inside > 0;
        ASSERT_EQ(mask->at(x, y), expected ? 1.0f : 0.0f) << "pixel " << x << ", " << y;
        if (!expected) {
          EXPECT_EQ(depth->at(x, y), 0.0f);
          for (int k = 0; k < 3; ++k) EXPECT_EQ(normal->at(x, y, k), 0.0f);
          for (int k = 0; k < 3; ++k) {
            EXPECT_FLOAT_EQ(color->at(x, y, k), shading::kBackground[k]);
          }
          EXPECT_EQ(color->at(x, y, 3), 0.0f);
          continue;
        }
        ++covered;
        Vec3 hit;
        ASSERT_TRUE(hitQuadPlane(camera, x + 0.5, y + 0.5, hit));
        double expectedDepth = camera.depthOf(hit);
        EXPECT_NEAR(depth->at(x, y), expectedDepth, 1e-4 * expectedDepth) << x << ", " << y;
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(normal->at(x, y, k), n[k], 1e-3) << x << "," << y;
        Vec3 toEye = camera.projection() == Projection::Perspective ? normalize(camera.eye() - hit)
                                                                    : -camera.forward();
        float rgb[3];
        shading::shade(n, toEye, rgb);
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(color->at(x, y, k), rgb[k], 1.0 / 255.0);
        EXPECT_EQ(color->at(x, y, 3), 1.0f);
      }
    }
    EXPECT_GT(covered, camera.width() * camera.height() / 8);  // the quad is really in view
    EXPECT_LT(covered, checked);                               // and so is background
  }

  static Rasterizer* rasterizer_;
};

Rasterizer* RasterTest::rasterizer_ = nullptr;

TEST(RasterTiling, TilesCoverTheFrameOnce) {
  std::vector<Tile> tiles = makeTiles(10, 7, 4);
  ASSERT_EQ(tiles.size(), 6u);
  std::vector<int> hits(70, 0);
  for (const Tile& t : tiles)
    for (int y = t.y; y < t.y + t.height; ++y)
      for (int x = t.x; x < t.x + t.width; ++x) ++hits[y * 10 + x];
  for (int h : hits) EXPECT_EQ(h, 1);
}

TEST(RasterTiling, TileTransformMapsFramePixelsToTilePixels) {
  // A 100 x 60 frame; the tile holds columns 40..69 and rows 10..29 (top-down).
  const Tile tile{40, 10, 30, 20};
  Mat4 m = tileClipTransform(100, 60, tile);
  auto toTile = [&](double frameX, double frameYDown) {
    double ndcX = 2.0 * frameX / 100 - 1, ndcY = 1.0 - 2.0 * frameYDown / 60;
    double clipX = m[0] * ndcX + m[12], clipY = m[5] * ndcY + m[13];
    // GL window coordinates of the tile (y up), then top-down rows of the tile.
    return std::pair<double, double>{(clipX + 1) * 0.5 * 30, 20 - (clipY + 1) * 0.5 * 20};
  };
  auto [x0, y0] = toTile(40.5, 10.5);
  EXPECT_NEAR(x0, 0.5, 1e-5);
  EXPECT_NEAR(y0, 0.5, 1e-5);
  auto [x1, y1] = toTile(69.5, 29.5);
  EXPECT_NEAR(x1, 29.5, 1e-5);
  EXPECT_NEAR(y1, 19.5, 1e-5);
  // Reversed depth: near (z = -1) -> 1, far (z = 1) -> 0.
  EXPECT_FLOAT_EQ(m[10] * -1.0f + m[14], 1.0f);
  EXPECT_FLOAT_EQ(m[10] * 1.0f + m[14], 0.0f);
}

TEST(RasterShaders, ConstantsComeFromShadingHeader) {
  EXPECT_EQ(glslFloat(40.0f), "40.0");
  EXPECT_EQ(std::stof(glslFloat(shading::kFrontAlbedo[1])), shading::kFrontAlbedo[1]);
  std::string fragment = surfaceFragmentShader();
  EXPECT_NE(fragment.find("const float kShininess = " + glslFloat(shading::kShininess)),
            std::string::npos);
  EXPECT_NE(fragment.find(glslFloat(shading::kBackAlbedo[2])), std::string::npos);
}

TEST_F(RasterTest, ReportsItsDevice) {
  const DeviceInfo& device = rasterizer().device();
  EXPECT_FALSE(device.renderer.empty());
  EXPECT_FALSE(device.vendor.empty());
  EXPECT_NE(device.version.find("4."), std::string::npos) << device.version;
  EXPECT_TRUE(device.eglPlatform == "device" || device.eglPlatform == "surfaceless");
  std::printf("renderer: %s | vendor: %s | version: %s | EGL platform: %s\n",
              device.renderer.c_str(), device.vendor.c_str(), device.version.c_str(),
              device.eglPlatform.c_str());
}

TEST_F(RasterTest, PerspectiveQuadFlatShading) {
  Camera camera = perspectiveCamera();
  ImageSet images = rasterizer().render(tiltedQuad(), camera, allPasses(), Shading::Flat);
  expectTiltedQuad(images, camera);
}

TEST_F(RasterTest, PerspectiveQuadSmoothShading) {
  Camera camera = perspectiveCamera(80, 50);
  ImageSet images = rasterizer().render(tiltedQuad(), camera, allPasses(), Shading::Smooth);
  expectTiltedQuad(images, camera);
}

TEST_F(RasterTest, OrthographicQuad) {
  Camera camera = orthographicCamera();
  ImageSet images = rasterizer().render(tiltedQuad(), camera, allPasses(), Shading::Flat);
  expectTiltedQuad(images, camera);
}

TEST_F(RasterTest, OnlyTheSelectedPassesAreReturned) {
  PassSelection passes;
  passes.depth = true;
  ImageSet images = rasterizer().render(tiltedQuad(), perspectiveCamera(), passes, Shading::Flat);
  EXPECT_EQ(images.passes.size(), 1u);
  EXPECT_NE(images.find(pass::kDepth), nullptr);
  EXPECT_TRUE(images.supersampledMask.empty());
  EXPECT_EQ(images.supersample, 1);
}

TEST_F(RasterTest, WorldPointLandsOnThePixelCameraProjectNames) {
  Camera camera = perspectiveCamera(64, 48);
  const int pixels[][2] = {{5, 7}, {60, 3}, {31, 40}, {0, 47}, {63, 0}};
  for (auto [i, j] : pixels) {
    // A point at depth 4.3 on the ray through the centre of pixel (i, j), and a square of half
    // size 0.3 px around it facing the camera: only that pixel's centre can be covered.
    Ray ray = camera.rayThrough(i + 0.5, j + 0.5);
    Vec3 p = ray.origin + ray.direction * (4.3 / dot(ray.direction, camera.forward()));
    Vec3 projected = camera.project(p);
    ASSERT_NEAR(projected.x, i + 0.5, 1e-9);
    ASSERT_NEAR(projected.y, j + 0.5, 1e-9);
    double h = 0.3 / camera.pixelsPerUnit(camera.depthOf(p));
    Vec3 r = camera.right() * h, u = camera.trueUp() * h;
    TriangleMesh mesh = quad(p - r - u, p + r - u, p + r + u, p - r + u);
    PassSelection passes;
    passes.mask = true;
    Image mask = rasterizer().render(mesh, camera, passes, Shading::Flat).passes[pass::kMask];
    for (int y = 0; y < 48; ++y)
      for (int x = 0; x < 64; ++x)
        ASSERT_EQ(mask.at(x, y), (x == i && y == j) ? 1.0f : 0.0f) << i << "," << j;
  }
}

TEST_F(RasterTest, BackFacesKeepTheirWindingNormalAndGetTheBackAlbedo) {
  // The same quad wound clockwise as seen from the camera.
  TriangleMesh mesh = quad(kQuad[0], kQuad[3], kQuad[2], kQuad[1]);
  Camera camera = perspectiveCamera();
  ImageSet images = rasterizer().render(mesh, camera, allPasses(), Shading::Flat);
  const Vec3 n = -tiltedQuadNormal();
  int checked = 0;
  for (int y = 0; y < camera.height(); ++y) {
    for (int x = 0; x < camera.width(); ++x) {
      if (insideDistance(camera, quadCorners(), x + 0.5, y + 0.5) < 0.01) continue;
      Vec3 hit;
      ASSERT_TRUE(hitQuadPlane(camera, x + 0.5, y + 0.5, hit));
      for (int k = 0; k < 3; ++k) EXPECT_NEAR(images.passes[pass::kNormal].at(x, y, k), n[k], 1e-3);
      float rgb[3];
      shading::shade(n, normalize(camera.eye() - hit), rgb);
      for (int k = 0; k < 3; ++k)
        EXPECT_NEAR(images.passes[pass::kColor].at(x, y, k), rgb[k], 1e-3);
      ++checked;
    }
  }
  EXPECT_GT(checked, 100);
  // The back albedo is bluish: blue above red.
  float rgb[3];
  shading::shade(n, -camera.forward(), rgb);
  EXPECT_GT(rgb[2], rgb[0]);
}

TEST_F(RasterTest, SmoothShadingUsesTheInterpolatedVertexNormal) {
  TriangleMesh mesh = tiltedQuad();
  // Vertex normals that differ from the face normal and from each other (not unit length:
  // the shader normalises after interpolation).
  mesh.normals = {Vec3f(0, 0, 2), Vec3f(0, 0, 2), Vec3f(0.6f, 0, 0.8f), Vec3f(0.6f, 0, 0.8f)};
  mesh.indices = {0, 1, 2, 0, 2, 3};
  Camera camera = perspectiveCamera();
  ImageSet images = rasterizer().render(mesh, camera, allPasses(), Shading::Smooth);
  // From the bottom edge (+Z) to the top edge (0.6, 0, 0.8) the normal turns about Y: every
  // pixel's normal is a unit vector with y = 0, and both ends of the turn occur.
  const Image& normal = images.passes[pass::kNormal];
  double minX = 1, maxX = -1;
  int covered = 0;
  for (int y = 0; y < camera.height(); ++y) {
    for (int x = 0; x < camera.width(); ++x) {
      if (images.passes[pass::kMask].at(x, y) == 0.0f) continue;
      ++covered;
      Vec3 n{normal.at(x, y, 0), normal.at(x, y, 1), normal.at(x, y, 2)};
      EXPECT_NEAR(length(n), 1.0, 1e-5);
      EXPECT_NEAR(n.y, 0.0, 1e-6);
      minX = std::min(minX, n.x);
      maxX = std::max(maxX, n.x);
      float rgb[3];
      Vec3 hit;
      ASSERT_TRUE(hitQuadPlane(camera, x + 0.5, y + 0.5, hit));
      shading::shade(n, normalize(camera.eye() - hit), rgb);
      for (int k = 0; k < 3; ++k) {
        EXPECT_NEAR(images.passes[pass::kColor].at(x, y, k), rgb[k], 1e-4);
      }
    }
  }
  EXPECT_GT(covered, 100);
  EXPECT_LT(minX, 0.05);
  EXPECT_GT(maxX, 0.5);
}

TEST_F(RasterTest, SupersampledMaskMatchesCameraAndOutputMask) {
  Camera camera = perspectiveCamera(64, 48);
  const int S = 4;
  ImageSet images = rasterizer().render(tiltedQuad(), camera, allPasses(S), Shading::Flat);
  ASSERT_EQ(images.supersample, S);
  const Mask& big = images.supersampledMask;
  ASSERT_EQ(big.width, 64 * S);
  ASSERT_EQ(big.height, 48 * S);
  ASSERT_EQ(big.covered.size(), size_t{64} * S * 48 * S);
  // Exact against the supersampled camera.
  Camera bigCamera = camera.scaled(S);
  for (int y = 0; y < big.height; ++y) {
    for (int x = 0; x < big.width; ++x) {
      double inside = insideDistance(bigCamera, quadCorners(), x + 0.5, y + 0.5);
      if (std::fabs(inside) < 1e-3) continue;
      ASSERT_EQ(big.at(x, y), inside > 0 ? 1 : 0) << x << ", " << y;
    }
  }
  // Block majority agrees with the output mask except where a block is split evenly or at
  // the quad's corners.
  const Image& mask = images.passes[pass::kMask];
  int disagree = 0;
  for (int y = 0; y < 48; ++y) {
    for (int x = 0; x < 64; ++x) {
      int count = 0;
      for (int v = 0; v < S; ++v)
        for (int u = 0; u < S; ++u) count += big.at(x * S + u, y * S + v);
      if (count == S * S / 2) continue;
      if ((count > S * S / 2) != (mask.at(x, y) > 0.5f)) ++disagree;
    }
  }
  EXPECT_LE(disagree, 4);
}

TEST_F(RasterTest, LargeFramesAndSupersampledMasksAreTiled) {
  // 2100 px wide: two frame tiles (2048 cap); S = 8 makes 16800 x 400: five coverage tiles
  // (4096 cap). The view is shifted so that the quad straddles the seams at x = 2048 (frame)
  // and x = 16384 (coverage).
  Camera camera(Vec3{0.4 - 13.75, 0.3, 5}, Vec3{-13.75, 0.2, 0}, Vec3{0, 1, 0}, 10.0,
                Projection::Perspective, 2.0, 2100, 50, 1.0, 10.0);
  PassSelection passes;
  passes.mask = passes.depth = true;
  passes.supersample = 8;
  TriangleMesh mesh = tiltedQuad();
  ImageSet images = rasterizer().render(mesh, camera, passes, Shading::Flat);
  const Image& mask = images.passes[pass::kMask];
  const Image& depth = images.passes[pass::kDepth];
  int covered = 0;
  for (int y = 0; y < camera.height(); ++y) {
    for (int x = 0; x < camera.width(); ++x) {
      double inside = insideDistance(camera, quadCorners(), x + 0.5, y + 0.5);
      if (std::fabs(inside) < 1e-3) continue;
      ASSERT_EQ(mask.at(x, y), inside > 0 ? 1.0f : 0.0f) << x << ", " << y;
      if (inside > 0) {
        ++covered;
        Vec3 hit;
        ASSERT_TRUE(hitQuadPlane(camera, x + 0.5, y + 0.5, hit));
        ASSERT_NEAR(depth.at(x, y), camera.depthOf(hit), 1e-4 * camera.depthOf(hit));
      }
    }
  }
  EXPECT_GT(covered, 1000);
  EXPECT_EQ(mask.at(2047, 25), 1.0f);
  EXPECT_EQ(mask.at(2048, 25), 1.0f);
  Camera bigCamera = camera.scaled(8);
  const Mask& big = images.supersampledMask;
  ASSERT_EQ(big.width, 16800);
  int bigCovered = 0;
  for (int y = 0; y < big.height; ++y) {
    for (int x = 0; x < big.width; ++x) {
      double inside = insideDistance(bigCamera, quadCorners(), x + 0.5, y + 0.5);
      if (std::fabs(inside) < 1e-2) continue;
      ASSERT_EQ(big.at(x, y), inside > 0 ? 1 : 0) << x << ", " << y;
      bigCovered += inside > 0;
    }
  }
  EXPECT_GT(bigCovered, 64 * 1000);
  EXPECT_EQ(big.at(16383, 200), 1);
  EXPECT_EQ(big.at(16384, 200), 1);
}

TEST_F(RasterTest, WireframeDiffersFromColorOnlyAlongEdges) {
  Camera camera = perspectiveCamera(96, 72);
  PassSelection passes;
  passes.color = passes.wireframe = true;
  TriangleMesh mesh = tiltedQuad();
  ImageSet images = rasterizer().render(mesh, camera, passes, Shading::Flat);
  const Image& color = images.passes[pass::kColor];
  const Image& wire = images.passes[pass::kWireframe];
  std::vector<Vec3> px;
  for (const Vec3& p : quadCorners()) px.push_back(camera.project(p));
  int drawn = 0, onDiagonal = 0;
  for (int y = 0; y < camera.height(); ++y) {
    for (int x = 0; x < camera.width(); ++x) {
      bool same = true;
      for (int k = 0; k < 4; ++k) same = same && wire.at(x, y, k) == color.at(x, y, k);
      if (same) continue;
      ++drawn;
      double cx = x + 0.5, cy = y + 0.5;
      double d =
          std::min({segmentDistance(px[0], px[1], cx, cy), segmentDistance(px[1], px[2], cx, cy),
                    segmentDistance(px[2], px[3], cx, cy), segmentDistance(px[3], px[0], cx, cy)});
      double diagonal = segmentDistance(px[0], px[2], cx, cy);
      ASSERT_LE(std::min(d, diagonal), 1.0) << "pixel " << x << ", " << y << " is off the edges";
      onDiagonal += diagonal < d;
      for (int k = 0; k < 3; ++k) {
        EXPECT_NEAR(wire.at(x, y, k), shading::srgbToLinear(shading::kWireColor[k]), 0.6f / 255);
      }
      EXPECT_EQ(wire.at(x, y, 3), 1.0f);
    }
  }
  EXPECT_GT(drawn, 150);      // the outline is roughly 2 * (60 + 45) px long
  EXPECT_GT(onDiagonal, 30);  // triangle edges include the diagonal

  // With explicit lines (the quad's outline), the diagonal is not drawn.
  mesh.lines = {0, 1, 1, 2, 2, 3, 3, 0};
  images = rasterizer().render(mesh, camera, passes, Shading::Flat);
  onDiagonal = 0;
  for (int y = 0; y < camera.height(); ++y) {
    for (int x = 0; x < camera.width(); ++x) {
      if (images.passes[pass::kWireframe].at(x, y, 0) == images.passes[pass::kColor].at(x, y, 0))
        continue;
      double cx = x + 0.5, cy = y + 0.5;
      double d =
          std::min({segmentDistance(px[0], px[1], cx, cy), segmentDistance(px[1], px[2], cx, cy),
                    segmentDistance(px[2], px[3], cx, cy), segmentDistance(px[3], px[0], cx, cy)});
      EXPECT_LE(d, 1.0) << x << ", " << y;
    }
  }
}

TEST_F(RasterTest, HiddenEdgesDoNotShowInTheWireframe) {
  Camera camera = perspectiveCamera(96, 72);
  // A big quad in front (z = 1) and a small one behind it (z = -1), fully hidden.
  TriangleMesh front = quad({-3, -3, 1}, {3, -3, 1}, {3, 3, 1}, {-3, 3, 1});
  TriangleMesh back = quad({-0.5, -0.5, -1}, {0.5, -0.5, -1}, {0.5, 0.5, -1}, {-0.5, 0.5, -1});
  front.lines = {0, 1, 1, 2, 2, 3, 3, 0};  // the front quad's outline is outside the view
  TriangleMesh both = append(front, back);
  both.lines = front.lines;
  // Lines of the back quad, by index after appending.
  for (uint32_t i : {4u, 5u, 5u, 6u, 6u, 7u, 7u, 4u}) both.lines.push_back(i);
  PassSelection passes;
  passes.color = passes.wireframe = true;
  ImageSet images = rasterizer().render(both, camera, passes, Shading::Flat);
  EXPECT_EQ(images.passes[pass::kWireframe].pixels, images.passes[pass::kColor].pixels);

  // Without the front quad the same edges do show: the test above can fail.
  back.lines = {0, 1, 1, 2, 2, 3, 3, 0};
  images = rasterizer().render(back, camera, passes, Shading::Flat);
  EXPECT_NE(images.passes[pass::kWireframe].pixels, images.passes[pass::kColor].pixels);
}

TEST_F(RasterTest, NearerSurfaceWinsRegardlessOfDrawOrder) {
  Camera camera = perspectiveCamera();
  TriangleMesh nearQuad =
      quad({-0.5, -0.5, 1.5}, {0.5, -0.5, 1.5}, {0.5, 0.5, 1.5}, {-0.5, 0.5, 1.5});
  TriangleMesh farQuad = quad({-2, -2, -1}, {2, -2, -1}, {2, 2, -1}, {-2, 2, -1});
  PassSelection passes;
  passes.depth = true;
  for (const TriangleMesh& mesh : {append(nearQuad, farQuad), append(farQuad, nearQuad)}) {
    Image depth = rasterizer().render(mesh, camera, passes, Shading::Flat).passes[pass::kDepth];
    Vec3 centre = camera.project({0, 0, 1.5});
    int cx = static_cast<int>(centre.x), cy = static_cast<int>(centre.y);
    Vec3 hit;
    Ray ray = camera.rayThrough(cx + 0.5, cy + 0.5);
    hit = ray.origin + ray.direction * ((1.5 - ray.origin.z) / ray.direction.z);
    EXPECT_NEAR(depth.at(cx, cy), camera.depthOf(hit), 1e-4);
  }
}

TEST_F(RasterTest, EmptyMeshGivesBackground) {
  ImageSet images =
      rasterizer().render(TriangleMesh{}, perspectiveCamera(), allPasses(2), Shading::Smooth);
  for (float v : images.passes[pass::kMask].pixels) ASSERT_EQ(v, 0.0f);
  for (uint8_t v : images.supersampledMask.covered) ASSERT_EQ(v, 0);
  const Image& color = images.passes[pass::kColor];
  EXPECT_FLOAT_EQ(color.at(3, 4, 1), shading::kBackground[1]);
  EXPECT_EQ(color.at(3, 4, 3), 0.0f);
}

TEST_F(RasterTest, MeshWithoutNormalsIsShadedFlat) {
  TriangleMesh mesh = tiltedQuad();
  mesh.normals.clear();
  Camera camera = perspectiveCamera();
  ImageSet images = rasterizer().render(mesh, camera, allPasses(), Shading::Smooth);
  expectTiltedQuad(images, camera);
}

TEST_F(RasterTest, RejectsBadMeshesAndCameras) {
  TriangleMesh mesh = tiltedQuad();
  mesh.indices.push_back(0);
  EXPECT_THROW(rasterizer().render(mesh, perspectiveCamera(), allPasses(), Shading::Flat),
               std::invalid_argument);
  mesh = tiltedQuad();
  mesh.indices[4] = 4;
  EXPECT_THROW(rasterizer().render(mesh, perspectiveCamera(), allPasses(), Shading::Flat),
               std::invalid_argument);
  mesh = tiltedQuad();
  mesh.normals.pop_back();
  EXPECT_THROW(rasterizer().render(mesh, perspectiveCamera(), allPasses(), Shading::Flat),
               std::invalid_argument);
  EXPECT_THROW(
      rasterizer().render(tiltedQuad(), perspectiveCamera(0, 10), allPasses(), Shading::Flat),
      std::invalid_argument);
  // Still usable afterwards.
  Camera camera = perspectiveCamera();
  expectTiltedQuad(rasterizer().render(tiltedQuad(), camera, allPasses(), Shading::Flat), camera);
}

// A UV sphere of radius r at the origin with smooth normals: 2 * rings * segments triangles.
TriangleMesh sphere(double r, int rings, int segments) {
  TriangleMesh mesh;
  for (int i = 0; i <= rings; ++i) {
    double theta = std::numbers::pi * i / rings;
    for (int j = 0; j <= segments; ++j) {
      double phi = 2 * std::numbers::pi * j / segments;
      Vec3 n{std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi)};
      mesh.positions.emplace_back(n * r);
      mesh.normals.emplace_back(n);
    }
  }
  for (int i = 0; i < rings; ++i) {
    for (int j = 0; j < segments; ++j) {
      uint32_t a = i * (segments + 1) + j, b = a + segments + 1;
      // Counter-clockwise seen from outside.
      for (uint32_t k : {a, a + 1, b, a + 1, b + 1, b}) mesh.indices.push_back(k);
    }
  }
  return mesh;
}

TEST_F(RasterTest, SphereOfAHundredThousandTriangles) {
  TriangleMesh mesh = sphere(1.0, 200, 250);  // 100,000 triangles
  Camera camera({0, 0, 4}, {0, 0, 0}, {0, 1, 0}, 40.0, Projection::Perspective, 2.0, 1024, 1024,
                2.0, 6.0);
  rasterizer().render(mesh, camera, allPasses(4), Shading::Smooth);  // warm-up
  auto start = std::chrono::steady_clock::now();
  ImageSet images = rasterizer().render(mesh, camera, allPasses(4), Shading::Smooth);
  double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  std::printf("1024^2 color+mask+depth+normal + S=4 mask, %zu triangles: %.1f ms\n",
              mesh.triangleCount(), ms);
  // Silhouette of a sphere seen from distance 4: a circle of angular radius asin(1/4).
  double radiusPx = std::tan(std::asin(0.25)) * camera.pixelsPerUnit(1.0);
  double area = 0;
  for (float v : images.passes[pass::kMask].pixels) area += v;
  EXPECT_NEAR(area, std::numbers::pi * radiusPx * radiusPx, 0.01 * area);
  // The centre pixel looks straight at the sphere: depth 3, normal +Z, the brightest colour.
  EXPECT_NEAR(images.passes[pass::kDepth].at(512, 512), 3.0, 1e-3);
  EXPECT_NEAR(images.passes[pass::kNormal].at(512, 512, 2), 1.0, 1e-3);
  double bigArea = 0;
  for (uint8_t v : images.supersampledMask.covered) bigArea += v;
  EXPECT_NEAR(bigArea / 16, area, 0.002 * area);
}

// A closed surface wound outward needs no back faces from outside (TriangleMesh::closedOutward):
// every pass comes out the same without them. With the eye inside (the near plane cuts it) the
// back faces are what is seen, and they are still drawn.
TEST_F(RasterTest, AClosedSurfaceSeenFromOutsideIsTheSameWithoutItsBackFaces) {
  TriangleMesh drawnBoth = sphere(1.0, 40, 56);
  TriangleMesh closed = drawnBoth;
  closed.closedOutward = true;
  PassSelection passes = allPasses(4);
  passes.antialias = 4;
  const Camera outside({0.3, 0.2, 4}, {0, 0, 0}, {0, 1, 0}, 40.0, Projection::Perspective, 2.0, 160,
                       120, 1.0, 10.0);
  const Camera inside({0, 0, 0.2}, {0, 0, 1}, {0, 1, 0}, 60.0, Projection::Perspective, 2.0, 160,
                      120, 0.05, 10.0);
  for (const Camera& camera : {outside, inside}) {
    ImageSet both = rasterizer().render(drawnBoth, camera, passes, Shading::Smooth);
    ImageSet front = rasterizer().render(closed, camera, passes, Shading::Smooth);
    for (const char* name : {pass::kColor, pass::kMask, pass::kDepth, pass::kNormal}) {
      EXPECT_EQ(both.passes[name].pixels, front.passes[name].pixels) << name;
    }
    EXPECT_EQ(both.supersampledMask.covered, front.supersampledMask.covered);
  }
  // Inside, only back faces face the eye: the picture is all back albedo, not background.
  ImageSet seenFromInside = rasterizer().render(closed, inside, passes, Shading::Smooth);
  for (float v : seenFromInside.passes[pass::kMask].pixels) ASSERT_EQ(v, 1.0f);
}

TEST_F(RasterTest, MillionsOfTriangles) {
  // A 1000 x 1000 grid of quads: 2 million triangles covering a square that fills the frame.
  const int n = 1000;
  TriangleMesh mesh;
  for (int y = 0; y <= n; ++y)
    for (int x = 0; x <= n; ++x) {
      mesh.positions.emplace_back(-1.0f + 2.0f * x / n, -1.0f + 2.0f * y / n, 0.0f);
      mesh.normals.emplace_back(0.0f, 0.0f, 1.0f);
    }
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      uint32_t a = y * (n + 1) + x, b = a + n + 1;
      for (uint32_t k : {a, a + 1, b + 1, a, b + 1, b}) mesh.indices.push_back(k);
    }
  Camera camera({0, 0, 3}, {0, 0, 0}, {0, 1, 0}, 30.0, Projection::Orthographic, 1.5, 256, 256, 1.0,
                5.0);
  PassSelection passes;
  passes.mask = passes.depth = true;
  ImageSet images = rasterizer().render(mesh, camera, passes, Shading::Smooth);
  // The grid is larger than the view: every pixel covered at depth 3, no cracks.
  for (float v : images.passes[pass::kMask].pixels) ASSERT_EQ(v, 1.0f);
  for (float v : images.passes[pass::kDepth].pixels) ASSERT_NEAR(v, 3.0f, 1e-5f);
}

// ---- Line overlays ----

using Rgba = std::array<uint8_t, 4>;

// An overlay segment projected to pixel coordinates, with its colour.
struct PixelSegment {
  Vec3 a, b;
  Rgba color;
};

std::vector<PixelSegment> projectOverlay(const Camera& camera, const LineOverlay& overlay) {
  std::vector<PixelSegment> out;
  for (size_t s = 0; s < overlay.segmentCount(); ++s) {
    out.push_back({camera.project(overlay.points[2 * s].toDouble()),
                   camera.project(overlay.points[2 * s + 1].toDouble()), overlay.colors[s]});
  }
  return out;
}

// The segment nearest to the pixel centre (x + 0.5, y + 0.5) and its distance.
const PixelSegment* nearestSegment(const std::vector<PixelSegment>& segments, int x, int y,
                                   double& distance) {
  const PixelSegment* best = nullptr;
  distance = 1e300;
  for (const PixelSegment& s : segments) {
    double d = segmentDistance(s.a, s.b, x + 0.5, y + 0.5);
    if (d < distance) {
      distance = d;
      best = &s;
    }
  }
  return best;
}

// Overlay colours are sRGB; the pass holds them in linear light, through an 8-bit framebuffer.
bool pixelHasColor(const Image& image, int x, int y, const Rgba& rgba) {
  for (int k = 0; k < 4; ++k) {
    const float expected = k < 3 ? shading::srgbToLinear(rgba[k] / 255.0f) : rgba[k] / 255.0f;
    if (std::abs(image.at(x, y, k) - expected) > 0.6f / 255) return false;
  }
  return true;
}

bool samePixel(const Image& a, const Image& b, int x, int y) {
  for (int k = 0; k < 4; ++k) {
    if (a.at(x, y, k) != b.at(x, y, k)) return false;
  }
  return true;
}

// Checks an overlay pass against the colour pass: pixel centres within `onLine` px of a
// segment hold its colour (when `visible` says they should), pixel centres farther than 1.5 px
// from every segment (the quads' corners are sqrt(2) px away) equal the colour pass exactly.
// Returns the number of line-coloured pixels.
template <typename Visible>
int expectOverlayPass(const Image& color, const Image& lines, const Camera& camera,
                      const std::vector<PixelSegment>& segments, Visible visible,
                      double onLine = 0.5) {
  EXPECT_EQ(lines.width, camera.width());
  EXPECT_EQ(lines.height, camera.height());
  EXPECT_EQ(lines.channels, 4);
  int drawn = 0;
  for (int y = 0; y < camera.height(); ++y) {
    for (int x = 0; x < camera.width(); ++x) {
      double d = 0;
      const PixelSegment* s = nearestSegment(segments, x, y, d);
      if (d > 1.5) {
        EXPECT_TRUE(samePixel(color, lines, x, y)) << "pixel " << x << ", " << y;
        continue;
      }
      // Where segments cross, the pixel may hold the other one's colour.
      bool lineColored = false;
      for (const PixelSegment& other : segments) {
        lineColored = lineColored || (segmentDistance(other.a, other.b, x + 0.5, y + 0.5) <= 1.5 &&
                                      pixelHasColor(lines, x, y, other.color));
      }
      drawn += lineColored;
      if (d < onLine && visible(x, y, *s)) {
        EXPECT_TRUE(lineColored) << "pixel " << x << ", " << y << " at " << d << " px";
      }
    }
  }
  return drawn;
}

Camera sphereCamera(int width = 160, int height = 120) {
  return Camera({0, 0, 4}, {0, 0, 0}, {0, 1, 0}, 40.0, Projection::Perspective, 2.0, width, height,
                1.0, 10.0);
}

PassSelection colorAndMask() {
  PassSelection passes;
  passes.color = passes.mask = true;
  return passes;
}

TEST_F(RasterTest, OverlayLinesInFrontOfASphere) {
  const TriangleMesh mesh = sphere(1.0, 48, 64);
  const Camera camera = sphereCamera();
  LineOverlay overlay;
  overlay.pass = "lines";
  // A horizontal line in front of the sphere across the whole frame, and a slanted one.
  overlay.points = {Vec3f(-3, 0.1f, 1.3f), Vec3f(3, 0.1f, 1.3f), Vec3f(-0.3f, -2, 1.2f),
                    Vec3f(0.2f, 2, 1.1f)};
  overlay.colors = {Rgba{250, 10, 20, 255}, Rgba{0, 200, 40, 255}};
  ImageSet images = rasterizer().render(mesh, camera, colorAndMask(), Shading::Smooth, {overlay});
  ASSERT_EQ(images.passes.size(), 3u);
  const Image& color = images.passes.at(pass::kColor);
  const Image& lines = images.passes.at("lines");
  const Image& mask = images.passes.at(pass::kMask);
  const std::vector<PixelSegment> segments = projectOverlay(camera, overlay);
  int overSphere = 0;
  expectOverlayPass(color, lines, camera, segments, [&](int x, int y, const PixelSegment&) {
    overSphere += mask.at(x, y) > 0;
    return true;
  });
  EXPECT_GT(overSphere, 100);  // the lines really cross the sphere
  // About 2 px wide: a horizontal line covers two pixel centres per column.
  int red = 0;
  for (int y = 0; y < camera.height(); ++y)
    for (int x = 0; x < camera.width(); ++x) red += pixelHasColor(lines, x, y, overlay.colors[0]);
  EXPECT_GE(red, 2 * camera.width() - 8);  // less where the green line crosses
  EXPECT_LE(red, 2 * camera.width());
  // The colour pass itself has no line in it.
  EXPECT_FALSE(pixelHasColor(color, 80, static_cast<int>(segments[0].a.y), overlay.colors[0]));
}

// ---- Anti-aliasing ----

// Pixels of an image whose alpha lies strictly between empty and covered.
int partialAlphaPixels(const Image& image) {
  int partial = 0;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x)
      partial += image.at(x, y, 3) > 0.01f && image.at(x, y, 3) < 0.99f;
  return partial;
}

// Multisampled colour: the outline's pixels blend surface and background (intermediate alpha
// and colour), the inside keeps the one-sample colour, and the mask, depth and normal passes
// (what the metrics read) are exactly the one-sample ones.
TEST_F(RasterTest, AntialiasingBlendsTheOutlineAndLeavesTheMetricPassesAlone) {
  const TriangleMesh mesh = sphere(1.0, 48, 64);
  const Camera camera = sphereCamera();
  PassSelection passes = allPasses();
  const ImageSet sharp = rasterizer().render(mesh, camera, passes, Shading::Smooth);
  EXPECT_EQ(partialAlphaPixels(sharp.passes.at(pass::kColor)), 0);
  for (int samples : {4, 8, 16}) {
    if (samples > rasterizer().device().maxSamples) continue;
    passes.antialias = samples;
    const ImageSet smooth = rasterizer().render(mesh, camera, passes, Shading::Smooth);
    const Image& color = smooth.passes.at(pass::kColor);
    const Image& mask = smooth.passes.at(pass::kMask);
    for (const char* name : {pass::kMask, pass::kDepth, pass::kNormal}) {
      EXPECT_EQ(smooth.passes.at(name).pixels, sharp.passes.at(name).pixels) << name << samples;
    }
    // Every outline pixel (covered, with an uncovered 4-neighbour, or the reverse) of a sphere
    // is partly covered; about the outline's length in pixels of them are.
    int outline = 0, blended = 0, insideDiffers = 0;
    for (int y = 1; y + 1 < camera.height(); ++y) {
      for (int x = 1; x + 1 < camera.width(); ++x) {
        const float m = mask.at(x, y);
        const bool edge = mask.at(x - 1, y) != m || mask.at(x + 1, y) != m ||
                          mask.at(x, y - 1) != m || mask.at(x, y + 1) != m;
        const float alpha = color.at(x, y, 3);
        if (edge && m > 0) {
          ++outline;
          blended += alpha < 0.999f;
        }
        if (!edge && m > 0) {
          EXPECT_EQ(alpha, 1.0f) << x << "," << y;
          const float one = sharp.passes.at(pass::kColor).at(x, y, 0);
          insideDiffers += std::fabs(color.at(x, y, 0) - one) > 2.5f / 255;  // 8-bit samples
        }
      }
    }
    EXPECT_GT(outline, 100);
    EXPECT_GT(blended, outline / 4) << samples << " samples";  // the others: wholly covered
    EXPECT_LT(insideDiffers, outline / 4) << "the inside is shaded once per pixel";
    EXPECT_GT(partialAlphaPixels(color), outline / 2);
  }
}

TEST_F(RasterTest, SamplePositionsLieInsideThePixelAndDiffer) {
  EXPECT_EQ(rasterizer().samplePositions(1), (std::vector<std::array<float, 2>>{{0.5f, 0.5f}}));
  ASSERT_GE(rasterizer().device().maxSamples, 4) << "llvmpipe and every GPU take 4x MSAA";
  const auto positions = rasterizer().samplePositions(4);
  ASSERT_EQ(positions.size(), 4u);
  std::printf("maxSamples %d; 4x pattern:", rasterizer().device().maxSamples);
  for (const auto& p : positions) std::printf(" (%.4f, %.4f)", p[0], p[1]);
  std::printf("\n");
  for (size_t i = 0; i < positions.size(); ++i) {
    EXPECT_GE(positions[i][0], 0.0f);
    EXPECT_LE(positions[i][0], 1.0f);
    EXPECT_GE(positions[i][1], 0.0f);
    EXPECT_LE(positions[i][1], 1.0f);
    for (size_t j = 0; j < i; ++j) EXPECT_NE(positions[i], positions[j]);
  }
  // More than the device takes: drawn with as many as it takes.
  const int most = rasterizer().device().maxSamples;
  EXPECT_EQ(rasterizer().samplesTaken(most * 2), most);
  EXPECT_EQ(rasterizer().samplePositions(most * 2).size(), static_cast<size_t>(most));
  PassSelection tooMany = allPasses();
  tooMany.antialias = most * 2;
  PassSelection most4 = allPasses();
  most4.antialias = most;
  const Camera camera = perspectiveCamera();
  EXPECT_EQ(rasterizer()
                .render(tiltedQuad(), camera, tooMany, Shading::Flat)
                .passes.at(pass::kColor)
                .pixels,
            rasterizer()
                .render(tiltedQuad(), camera, most4, Shading::Flat)
                .passes.at(pass::kColor)
                .pixels);
  PassSelection none = allPasses();
  none.antialias = 0;
  EXPECT_THROW(rasterizer().render(tiltedQuad(), camera, none, Shading::Flat),
               std::invalid_argument);
}

// Overlay lines and the wireframe are anti-aliased too: a slanted line's pixels blend into the
// surface beneath (colours between the line's and the surface's), and with one sample they do not.
TEST_F(RasterTest, AntialiasedOverlayLinesBlendIntoTheSurface) {
  const TriangleMesh mesh = sphere(1.0, 48, 64);
  const Camera camera = sphereCamera();
  LineOverlay overlay;
  overlay.pass = "lines";
  overlay.points = {Vec3f(-0.3f, -2, 1.2f), Vec3f(0.2f, 2, 1.1f)};
  overlay.colors = {Rgba{250, 10, 20, 255}};
  // Pixels the line touched (the overlay pass differs from the colour pass): the line's own
  // colour, or a blend of it and the surface.
  const auto linePixels = [&](const ImageSet& images) {
    const Image &lines = images.passes.at("lines"), &color = images.passes.at(pass::kColor);
    int pure = 0, blended = 0;
    for (int y = 0; y < lines.height; ++y) {
      for (int x = 0; x < lines.width; ++x) {
        double fromColor = 0, fromLine = 0;
        for (int c = 0; c < 3; ++c) {
          fromColor += std::fabs(lines.at(x, y, c) - color.at(x, y, c));
          fromLine +=
              std::fabs(lines.at(x, y, c) - shading::srgbToLinear(overlay.colors[0][c] / 255.0f));
        }
        if (fromColor < 0.02) continue;
        (fromLine < 0.02 ? pure : blended) += 1;
      }
    }
    return std::pair{pure, blended};
  };
  PassSelection passes = colorAndMask();
  passes.wireframe = true;
  const ImageSet sharp = rasterizer().render(mesh, camera, passes, Shading::Smooth, {overlay});
  passes.antialias = 4;
  const ImageSet smooth = rasterizer().render(mesh, camera, passes, Shading::Smooth, {overlay});
  const auto [sharpPure, sharpBlended] = linePixels(sharp);
  const auto [pure, blended] = linePixels(smooth);
  EXPECT_GT(sharpPure, 100);
  EXPECT_EQ(sharpBlended, 0);
  EXPECT_GT(blended, sharpPure / 2) << "a slanted line's edge pixels are blended";
  EXPECT_GT(pure, 0);
  // The wireframe's dark edges over the surface: more distinct grey levels when blended.
  const auto levels = [](const Image& image) {
    std::set<int> seen;
    for (int y = 0; y < image.height; ++y)
      for (int x = 0; x < image.width; ++x) seen.insert(static_cast<int>(image.at(x, y, 0) * 255));
    return seen.size();
  };
  EXPECT_GT(levels(smooth.passes.at(pass::kWireframe)), levels(sharp.passes.at(pass::kWireframe)));
}

TEST_F(RasterTest, OccludedOverlayIsHiddenBehindTheSurface) {
  const TriangleMesh mesh = sphere(1.0, 48, 64);
  const Camera camera = sphereCamera();
  LineOverlay behind;
  behind.pass = "behind";
  behind.points = {Vec3f(-0.4f, 0.2f, -1.3f), Vec3f(0.4f, -0.1f, -1.3f)};
  behind.colors = {Rgba{255, 255, 0, 255}};
  ImageSet images = rasterizer().render(mesh, camera, colorAndMask(), Shading::Smooth, {behind});
  EXPECT_EQ(images.passes.at("behind").pixels, images.passes.at(pass::kColor).pixels);

  // Drawn over everything, the same line shows.
  behind.occluded = false;
  images = rasterizer().render(mesh, camera, colorAndMask(), Shading::Smooth, {behind});
  const std::vector<PixelSegment> segments = projectOverlay(camera, behind);
  int drawn = expectOverlayPass(images.passes.at(pass::kColor), images.passes.at("behind"), camera,
                                segments, [](int, int, const PixelSegment&) { return true; });
  const double length =
      std::hypot(segments[0].b.x - segments[0].a.x, segments[0].b.y - segments[0].a.y);
  EXPECT_GT(drawn, 1.8 * length);

  // A line from behind the sphere out past its silhouette shows only outside it.
  LineOverlay out;
  out.pass = "out";
  out.points = {Vec3f(0, 0, -1.3f), Vec3f(4, 0.5f, -1.3f)};
  out.colors = {Rgba{255, 0, 255, 255}};
  images = rasterizer().render(mesh, camera, colorAndMask(), Shading::Smooth, {out});
  const Image& mask = images.passes.at(pass::kMask);
  // Distance to the silhouette: the sphere's outline is a circle about the image centre.
  const double radiusPx = std::tan(std::asin(0.25)) * camera.pixelsPerUnit(1.0);
  int shown = 0, hidden = 0;
  expectOverlayPass(images.passes.at(pass::kColor), images.passes.at("out"), camera,
                    projectOverlay(camera, out), [&](int x, int y, const PixelSegment& s) {
                      const double r = std::hypot(x + 0.5 - 80, y + 0.5 - 60);
                      if (std::fabs(r - radiusPx) < 2) return false;
                      const bool lineColored =
                          pixelHasColor(images.passes.at("out"), x, y, s.color);
                      if (mask.at(x, y) > 0) {
                        EXPECT_FALSE(lineColored) << x << ", " << y;
                        ++hidden;
                        return false;
                      }
                      ++shown;
                      return true;
                    });
  EXPECT_GT(hidden, 30);
  EXPECT_GT(shown, 30);
}

// The point of the tilted quad at bilinear coordinates (s, t).
Vec3f quadPoint(double s, double t) {
  return Vec3f((kQuad[0] * (1 - s) + kQuad[1] * s) * (1 - t) +
               (kQuad[3] * (1 - s) + kQuad[2] * s) * t);
}

// True when every pixel within `radius` pixels of (x, y) is covered.
bool coveredAround(const Image& mask, int x, int y, int radius) {
  for (int v = y - radius; v <= y + radius; ++v)
    for (int u = x - radius; u <= x + radius; ++u)
      if (u < 0 || v < 0 || u >= mask.width || v >= mask.height || mask.at(u, v) == 0) return false;
  return true;
}

TEST_F(RasterTest, OverlayLinesLyingOnTheSurfaceStayVisible) {
  // On a plane: across the tilted quad, along its diagonal (a shared triangle edge) and along
  // one of its outer edges, for both projections.
  auto onQuad = quadPoint;
  LineOverlay overlay;
  overlay.pass = "on";
  overlay.points = {onQuad(0.1, 0.2), onQuad(0.9, 0.7), Vec3f(kQuad[0]),
                    Vec3f(kQuad[2]),  Vec3f(kQuad[0]),  Vec3f(kQuad[1])};
  overlay.colors = {Rgba{255, 0, 0, 255}, Rgba{0, 0, 255, 255}, Rgba{0, 255, 0, 255}};
  for (const Camera& camera : {perspectiveCamera(96, 72), orthographicCamera(96, 72)}) {
    ImageSet images =
        rasterizer().render(tiltedQuad(), camera, colorAndMask(), Shading::Flat, {overlay});
    int drawn = expectOverlayPass(images.passes.at(pass::kColor), images.passes.at("on"), camera,
                                  projectOverlay(camera, overlay),
                                  [](int, int, const PixelSegment&) { return true; });
    EXPECT_GT(drawn, 150);
  }

  // On a curved mesh: the equator of a UV sphere runs along triangle edges. Seen from above,
  // its front half is visible all along and its back half hidden.
  const int rings = 48, segmentsPerRing = 64;
  const TriangleMesh mesh = sphere(1.0, rings, segmentsPerRing);
  const Camera camera({0, 2.5, 3}, {0, 0, 0}, {0, 1, 0}, 40.0, Projection::Perspective, 2.0, 160,
                      120, 1.0, 10.0);
  LineOverlay equator;
  equator.pass = "equator";
  const uint32_t first = (rings / 2) * (segmentsPerRing + 1);
  for (int j = 0; j < segmentsPerRing; ++j) {
    equator.points.push_back(mesh.positions[first + j]);
    equator.points.push_back(mesh.positions[first + j + 1]);
    equator.colors.push_back(Rgba{255, 255, 255, 255});
  }
  ImageSet images = rasterizer().render(mesh, camera, colorAndMask(), Shading::Smooth, {equator});
  const Image& color = images.passes.at(pass::kColor);
  const Image& lines = images.passes.at("equator");
  std::vector<PixelSegment> front, back;
  for (int j = 0; j < segmentsPerRing; ++j) {
    Vec3 a = equator.points[2 * j].toDouble(), b = equator.points[2 * j + 1].toDouble();
    Vec3 mid = (a + b) * 0.5;
    double facing = dot(normalize(mid), normalize(camera.eye() - mid));
    PixelSegment s{camera.project(a), camera.project(b), equator.colors[j]};
    if (facing > 0.2) front.push_back(s);
    if (facing < -0.2) back.push_back(s);
  }
  ASSERT_GT(front.size(), 10u);
  ASSERT_GT(back.size(), 10u);
  int frontChecked = 0, backChecked = 0;
  for (int y = 0; y < camera.height(); ++y) {
    for (int x = 0; x < camera.width(); ++x) {
      double dFront = 0, dBack = 0;
      nearestSegment(front, x, y, dFront);
      nearestSegment(back, x, y, dBack);
      if (dFront < 0.5 && dBack > 3) {
        EXPECT_TRUE(pixelHasColor(lines, x, y, equator.colors[0])) << x << ", " << y;
        ++frontChecked;
      }
      // Away from the outline: there the back half's 2 px reach past the silhouette.
      if (dBack < 0.7 && dFront > 3 && coveredAround(images.passes.at(pass::kMask), x, y, 2)) {
        EXPECT_TRUE(samePixel(color, lines, x, y)) << x << ", " << y;
        ++backChecked;
      }
    }
  }
  EXPECT_GT(frontChecked, 80);
  EXPECT_GT(backChecked, 80);
}

TEST_F(RasterTest, OverlaysAreSeparatePassesAndBlendWithTheirAlpha) {
  const Camera camera = perspectiveCamera(96, 72);
  LineOverlay a, b;
  a.pass = "a";
  a.points = {Vec3f(-1, 0, 1), Vec3f(1, 0.5f, 1)};
  a.colors = {Rgba{255, 0, 0, 128}};
  b.pass = "b";
  b.points = {Vec3f(0, -1, 1), Vec3f(0.2f, 1, 1)};
  b.colors = {Rgba{0, 0, 255, 255}};
  // The colour pass is not asked for; the overlays still start from it.
  PassSelection passes;
  passes.depth = true;
  ImageSet images = rasterizer().render(tiltedQuad(), camera, passes, Shading::Flat, {a, b});
  EXPECT_EQ(images.passes.size(), 3u);
  EXPECT_EQ(images.find(pass::kColor), nullptr);
  PassSelection colorOnly;
  colorOnly.color = true;
  const Image color =
      rasterizer().render(tiltedQuad(), camera, colorOnly, Shading::Flat).passes.at(pass::kColor);
  const std::vector<PixelSegment> segA = projectOverlay(camera, a),
                                  segB = projectOverlay(camera, b);
  const float alpha = 128 / 255.0f;
  int blended = 0;
  for (int y = 0; y < camera.height(); ++y) {
    for (int x = 0; x < camera.width(); ++x) {
      double dA = 0, dB = 0;
      nearestSegment(segA, x, y, dA);
      nearestSegment(segB, x, y, dB);
      // Each pass holds only its own overlay.
      if (dA > 1.5) {
        EXPECT_TRUE(samePixel(color, images.passes.at("a"), x, y)) << x << "," << y;
      }
      if (dB > 1.5) {
        EXPECT_TRUE(samePixel(color, images.passes.at("b"), x, y)) << x << "," << y;
      }
      if (dA < 0.5) {
        const Image& pa = images.passes.at("a");
        EXPECT_NEAR(pa.at(x, y, 0), alpha + (1 - alpha) * color.at(x, y, 0), 1e-5);
        EXPECT_NEAR(pa.at(x, y, 1), (1 - alpha) * color.at(x, y, 1), 1e-5);
        EXPECT_NEAR(pa.at(x, y, 3), alpha + (1 - alpha) * color.at(x, y, 3), 1e-5);
        ++blended;
      }
    }
  }
  EXPECT_GT(blended, 50);
}

TEST_F(RasterTest, OverlayCrossingTheNearPlaneIsCut) {
  // From in front of the sphere to behind the eye (z = 4): only the part deeper than the near
  // plane (depth 1, z <= 3) may be drawn, where Camera::project puts it.
  const Camera camera = sphereCamera();
  LineOverlay overlay;
  overlay.pass = "near";
  overlay.points = {Vec3f(0.1f, 0.05f, 1.5f), Vec3f(0.3f, 0.15f, 8)};
  overlay.colors = {Rgba{0, 255, 255, 255}};
  overlay.occluded = false;
  ImageSet images =
      rasterizer().render(sphere(1.0, 24, 32), camera, colorAndMask(), Shading::Smooth, {overlay});
  // The visible part ends on the near plane: z = 3, at t = 1.5 / 6.5 along the segment.
  const double t = 1.5 / 6.5;
  LineOverlay visible = overlay;
  visible.points[1] =
      Vec3f(0.1f + 0.2f * static_cast<float>(t), 0.05f + 0.1f * static_cast<float>(t), 3.0f);
  int drawn = expectOverlayPass(images.passes.at(pass::kColor), images.passes.at("near"), camera,
                                projectOverlay(camera, visible),
                                [](int, int, const PixelSegment&) { return true; });
  EXPECT_GT(drawn, 20);
}

TEST_F(RasterTest, OverlaysAreTiledLikeTheOtherPasses) {
  // The frame of LargeFramesAndSupersampledMasksAreTiled: the quad straddles x = 2048.
  Camera camera(Vec3{0.4 - 13.75, 0.3, 5}, Vec3{-13.75, 0.2, 0}, Vec3{0, 1, 0}, 10.0,
                Projection::Perspective, 2.0, 2100, 50, 1.0, 10.0);
  LineOverlay overlay;
  overlay.pass = "seam";
  overlay.points = {quadPoint(0.02, 0.3), quadPoint(0.98, 0.6)};
  overlay.colors = {Rgba{255, 128, 0, 255}};
  ImageSet images =
      rasterizer().render(tiltedQuad(), camera, colorAndMask(), Shading::Flat, {overlay});
  const std::vector<PixelSegment> segments = projectOverlay(camera, overlay);
  ASSERT_LT(std::min(segments[0].a.x, segments[0].b.x), 2040);
  ASSERT_GT(std::max(segments[0].a.x, segments[0].b.x), 2056);
  const Image& lines = images.passes.at("seam");
  int drawn = expectOverlayPass(images.passes.at(pass::kColor), lines, camera, segments,
                                [](int, int, const PixelSegment&) { return true; });
  EXPECT_GT(drawn, 100);
  int atSeam = 0;
  for (int y = 0; y < camera.height(); ++y) {
    atSeam += pixelHasColor(lines, 2047, y, overlay.colors[0]) +
              pixelHasColor(lines, 2048, y, overlay.colors[0]);
  }
  EXPECT_GE(atSeam, 2);
}

TEST_F(RasterTest, RejectsMalformedOverlays) {
  const Camera camera = perspectiveCamera();
  LineOverlay good;
  good.pass = "cage";
  good.points = {Vec3f(0, 0, 0), Vec3f(1, 0, 0)};
  good.colors = {Rgba{1, 2, 3, 255}};
  auto rejects = [&](const std::vector<LineOverlay>& overlays) {
    EXPECT_THROW(rasterizer().render(tiltedQuad(), camera, colorAndMask(), Shading::Flat, overlays),
                 std::invalid_argument);
  };
  LineOverlay bad = good;
  bad.points.push_back(Vec3f(0, 1, 0));
  rejects({bad});
  bad = good;
  bad.colors.push_back(Rgba{0, 0, 0, 255});
  rejects({bad});
  bad = good;
  bad.pass.clear();
  rejects({bad});
  for (const char* builtIn :
       {pass::kColor, pass::kMask, pass::kDepth, pass::kNormal, pass::kWireframe}) {
    bad = good;
    bad.pass = builtIn;
    rejects({bad});
  }
  rejects({good, good});
  bad = good;
  bad.points[1].y = std::numeric_limits<float>::quiet_NaN();
  rejects({bad});
  // Even when no other pass is asked for.
  EXPECT_THROW(rasterizer().render(tiltedQuad(), camera, PassSelection{}, Shading::Flat, {bad}),
               std::invalid_argument);
  // An overlay without segments is the colour pass; the rasteriser is still usable.
  LineOverlay empty;
  empty.pass = "empty";
  ImageSet images =
      rasterizer().render(tiltedQuad(), camera, colorAndMask(), Shading::Flat, {empty, good});
  EXPECT_EQ(images.passes.at("empty").pixels, images.passes.at(pass::kColor).pixels);
  EXPECT_EQ(images.passes.size(), 4u);
}

// ---- Normal-map shading ----

// A W x H normal map whose normals turn smoothly with s and t (differently in each), so a
// flipped or shifted lookup would show.
std::shared_ptr<const Image> smoothNormalMap(int width, int height) {
  auto map = std::make_shared<Image>(width, height, 3);
  for (int j = 0; j < height; ++j) {
    for (int i = 0; i < width; ++i) {
      const double s = (i + 0.5) / width, t = (j + 0.5) / height;
      Vec3 n = normalize(Vec3{0.6 * s - 0.2, 0.5 * t * t - 0.3, 1.0});
      for (int k = 0; k < 3; ++k) map->at(i, j, k) = static_cast<float>(n[k]);
    }
  }
  return map;
}

// What GL_LINEAR with clamp-to-edge reads at (s, t), renormalised.
Vec3 bilinearNormal(const Image& map, double s, double t) {
  const double x = s * map.width - 0.5, y = t * map.height - 0.5;
  const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
  const double fx = x - x0, fy = y - y0;
  auto texel = [&](int i, int j) {
    i = std::clamp(i, 0, map.width - 1);
    j = std::clamp(j, 0, map.height - 1);
    return Vec3{map.at(i, j, 0), map.at(i, j, 1), map.at(i, j, 2)};
  };
  return normalize((texel(x0, y0) * (1 - fx) + texel(x0 + 1, y0) * fx) * (1 - fy) +
                   (texel(x0, y0 + 1) * (1 - fx) + texel(x0 + 1, y0 + 1) * fx) * fy);
}

TEST_F(RasterTest, NormalMapShadingSamplesTheMapBilinearly) {
  // The tilted quad is a rectangle, so its texture coordinates are affine over all of it:
  // s along kQuad[0] -> kQuad[1], t along kQuad[0] -> kQuad[3].
  TriangleMesh mesh = tiltedQuad();
  mesh.texcoords = {Vec2f{0, 0}, Vec2f{1, 0}, Vec2f{1, 1}, Vec2f{0, 1}};
  mesh.normalMap = smoothNormalMap(7, 5);
  const Vec3 e1 = kQuad[1] - kQuad[0], e2 = kQuad[3] - kQuad[0];
  for (const Camera& camera : {perspectiveCamera(80, 60), orthographicCamera(80, 60)}) {
    ImageSet images = rasterizer().render(mesh, camera, allPasses(), Shading::NormalMap);
    const Image& normal = images.passes.at(pass::kNormal);
    const Image& color = images.passes.at(pass::kColor);
    int checked = 0;
    double worst = 0;
    for (int y = 0; y < camera.height(); ++y) {
      for (int x = 0; x < camera.width(); ++x) {
        if (insideDistance(camera, quadCorners(), x + 0.5, y + 0.5) < 0.01) continue;
        Vec3 hit;
        ASSERT_TRUE(hitQuadPlane(camera, x + 0.5, y + 0.5, hit));
        const double s = dot(hit - kQuad[0], e1) / dot(e1, e1);
        const double t = dot(hit - kQuad[0], e2) / dot(e2, e2);
        const Vec3 expected = bilinearNormal(*mesh.normalMap, s, t);
        const Vec3 got{normal.at(x, y, 0), normal.at(x, y, 1), normal.at(x, y, 2)};
        EXPECT_NEAR(length(got), 1.0, 1e-5);
        worst = std::max(worst, length(got - expected));
        Vec3 toEye = camera.projection() == Projection::Perspective ? normalize(camera.eye() - hit)
                                                                    : -camera.forward();
        float rgb[3];
        shading::shade(got, toEye, rgb);
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(color.at(x, y, k), rgb[k], 1e-4);
        ++checked;
      }
    }
    EXPECT_GT(checked, 500);
    // Neighbouring texels differ by about 0.1: a lookup off by a texel, or flipped, is 1e-1 off;
    // GPUs weigh bilinear samples with 8 fractional bits (~0.1 / 256).
    std::printf("normal-map lookup: worst normal error %.2e over %d pixels\n", worst, checked);
    EXPECT_LT(worst, 2e-3);
  }
}

TEST_F(RasterTest, NormalMapShadingNeedsTheMapAndTexcoords) {
  const Camera camera = perspectiveCamera();
  TriangleMesh mesh = tiltedQuad();
  EXPECT_THROW(rasterizer().render(mesh, camera, allPasses(), Shading::NormalMap),
               std::invalid_argument);
  mesh.normalMap = smoothNormalMap(4, 4);
  EXPECT_THROW(rasterizer().render(mesh, camera, allPasses(), Shading::NormalMap),
               std::invalid_argument);
  mesh.texcoords = {Vec2f{0, 0}, Vec2f{1, 0}, Vec2f{1, 1}};
  EXPECT_THROW(rasterizer().render(mesh, camera, allPasses(), Shading::NormalMap),
               std::invalid_argument);
  mesh.texcoords.push_back(Vec2f{0, 1});
  mesh.normalMap = std::make_shared<Image>(4, 4, 4, 0.5f);
  EXPECT_THROW(rasterizer().render(mesh, camera, allPasses(), Shading::NormalMap),
               std::invalid_argument);
  const int tooLarge = rasterizer().device().maxTextureSize + 1;
  ASSERT_GT(tooLarge, 1);
  mesh.normalMap = std::make_shared<Image>(tooLarge, 1, 3, 0.5f);
  EXPECT_THROW(rasterizer().render(mesh, camera, allPasses(), Shading::NormalMap),
               std::invalid_argument);
  // The other shadings ignore a bad map, and the rasteriser is still usable.
  expectTiltedQuad(rasterizer().render(mesh, camera, allPasses(), Shading::Flat), camera);
  mesh.normalMap = smoothNormalMap(4, 4);
  ImageSet images = rasterizer().render(mesh, camera, allPasses(), Shading::NormalMap);
  EXPECT_GT(images.passes.at(pass::kNormal).at(32, 24, 2), 0.9f);
}

TEST(RasterThreads, TwoRasterizersOnTwoThreads) {
  auto work = [](int width, std::string& error, int& coveredCount) {
    try {
      Rasterizer rasterizer;
      Camera camera = perspectiveCamera(width, 48);
      for (int round = 0; round < 20; ++round) {
        PassSelection passes = allPasses(2);
        ImageSet images = rasterizer.render(tiltedQuad(), camera, passes, Shading::Smooth);
        int covered = 0;
        for (int y = 0; y < 48; ++y)
          for (int x = 0; x < width; ++x) {
            double inside = insideDistance(camera, quadCorners(), x + 0.5, y + 0.5);
            if (std::fabs(inside) < 1e-3) continue;
            if (images.passes[pass::kMask].at(x, y) != (inside > 0 ? 1.0f : 0.0f)) {
              throw std::runtime_error("wrong mask at round " + std::to_string(round));
            }
            covered += inside > 0;
          }
        coveredCount = covered;
      }
    } catch (const std::exception& e) {
      error = e.what();
    }
  };
  std::string error1, error2;
  int covered1 = 0, covered2 = 0;
  std::thread t1(work, 64, std::ref(error1), std::ref(covered1));
  std::thread t2(work, 80, std::ref(error2), std::ref(covered2));
  t1.join();
  t2.join();
  EXPECT_EQ(error1, "");
  EXPECT_EQ(error2, "");
  EXPECT_GT(covered1, 300);
  EXPECT_GT(covered2, 300);
}

}  // namespace
}  // namespace limn::render::raster
