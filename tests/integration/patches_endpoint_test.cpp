// method "patches" through the real `limn serve` process: every project mesh from a random view
// within a pixel of the exact outline; no crack where the reference is covered, at fine and
// coarse dicing; the patch image of a cube shows rings of levels around its corners; culling
// leaves the picture as it was; the GPU tessellator (llvmpipe here) draws the CPU's picture;
// bad parameters are 4xx naming the field.
#include <gtest/gtest.h>
#include <rapidjson/document.h>

#include <array>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "render/image/encode.h"
#include "render/subdiv/limit_surface.h"
#include "tests/integration/http_client.h"
#include "tests/integration/json_answer.h"
#include "tests/integration/server_process.h"
#include "tests/support/random_views.h"
#include "tests/support/shapes.h"

namespace limn::testing {
namespace {

class PatchesEndpointTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    server_ = new ServerProcess(ServerProcess::withConfig(R"({"workers": 2, "queueDepth": 16})"));
  }
  static void TearDownTestSuite() {
    EXPECT_EQ(server_->terminate(SIGTERM), 0);
    delete server_;
    server_ = nullptr;
  }
  static int port() { return server_->port(); }
  static ServerProcess* server_;
};
ServerProcess* PatchesEndpointTest::server_ = nullptr;

std::string patchesRequest(const NamedMesh& shape, int side, const std::string& params,
                           const std::string& outputs, uint64_t seed = 5) {
  render::subdiv::LimitSurface surface(shape.mesh);
  RandomView view = randomViews(surface.bounds(), 1, viewSeed(seed, shape.name), side)[0];
  return R"({"mesh": )" + requestMeshJson(shape.mesh) + R"(, "camera": )" +
         describeCamera(view.camera) + R"(, "method": "patches", "params": )" + params +
         R"(, "reference": true, "outputs": )" + outputs + "}";
}

render::Image image(const rapidjson::Value& images, const char* pass) {
  return render::image::decode(decodeBase64(images[pass]["data"].GetString()));
}

TEST_F(PatchesEndpointTest, EveryProjectMeshFromARandomViewIsWithinAPixel) {
  for (const NamedMesh& shape : ownShapes()) {
    HttpResponse r =
        post(port(), "/v1/render", patchesRequest(shape, 384, R"({"dicingRate": 1})", "[]"));
    ASSERT_EQ(r.status, 200) << shape.name << ": " << r.body.substr(0, 400);
    auto doc = parseJson(r.body);
    EXPECT_LE(doc["metrics"]["silhouette"]["hausdorffPx"].GetDouble(), 1.0) << shape.name;
    const auto& table = doc["stats"]["patchTable"];
    EXPECT_GT(table["patches"].GetUint64(), 0u) << shape.name;
    EXPECT_EQ(doc["stats"]["patches"].GetUint64(), table["patches"].GetUint64());
    EXPECT_EQ(table["clampedEdges"].GetUint64(), 0u) << shape.name;
  }
}

// A crack shows as a pixel the reference covers and the patches miss, inside the surface
// (away from its outline, where a pixel can go either way).
TEST_F(PatchesEndpointTest, NoCrackWhereTheReferenceIsCovered) {
  for (const NamedMesh& shape :
       selectShapes(ownShapes(), {"own_cube", "own_torus_12x8_creased", "own_cube_sharp_corners",
                                  "own_icosahedron_loop", "own_pawn_588"})) {
    for (const char* params :
         {R"({"dicingRate": 1, "isolation": 2})", R"({"dicingRate": 12, "isolation": 5})"}) {
      HttpResponse r =
          post(port(), "/v1/render", patchesRequest(shape, 256, params, R"(["mask"])"));
      ASSERT_EQ(r.status, 200) << shape.name << ": " << r.body.substr(0, 400);
      auto doc = parseJson(r.body);
      render::Image mask = image(doc["images"], "mask");
      render::Image exact = image(doc["reference"]["images"], "mask");
      auto covered = [](const render::Image& m, int x, int y) { return m.at(x, y, 0) > 0.5f; };
      int holes = 0, inside = 0;
      for (int y = 2; y + 2 < exact.height; ++y) {
        for (int x = 2; x + 2 < exact.width; ++x) {
          bool interior = true;
          for (int dy = -2; dy <= 2; ++dy) {
            for (int dx = -2; dx <= 2; ++dx) interior = interior && covered(exact, x + dx, y + dy);
          }
          if (!interior) continue;
          ++inside;
          holes += !covered(mask, x, y);
        }
      }
      EXPECT_GT(inside, 1000) << shape.name;
      EXPECT_EQ(holes, 0) << shape.name << " " << params;
    }
  }
}

// Level colours of the patch image (docs/api.md): hue by level; compared by chromaticity, as
// shading scales the brightness.
TEST_F(PatchesEndpointTest, CubePatchImageShowsRingsOfLevelsAroundTheCorners) {
  const std::string body =
      R"({"mesh": )" + requestMeshJson(selectShapes(ownShapes(), {"own_cube"})[0].mesh) +
      R"(, "camera": {"eye": [2.2, 1.7, 2.9], "width": 384, "height": 384}, "method": "patches",
          "params": {"isolation": 4, "dicingRate": 2}, "outputs": ["patches"]})";
  HttpResponse r = post(port(), "/v1/render", body);
  ASSERT_EQ(r.status, 200) << r.body.substr(0, 400);
  auto doc = parseJson(r.body);
  render::Image picture = image(doc["images"], "patches");
  const std::array<std::array<float, 3>, 3> levels = {
      std::array<float, 3>{0.25f, 0.70f, 0.30f}, {0.65f, 0.80f, 0.20f}, {0.95f, 0.80f, 0.15f}};
  std::array<int, 4> count{};  // levels 2, 3, 4 and grey end caps
  int coveredPixels = 0;
  for (int y = 0; y < picture.height; ++y) {
    for (int x = 0; x < picture.width; ++x) {
      if (picture.at(x, y, 3) < 0.5f) continue;
      ++coveredPixels;
      float r = picture.at(x, y, 0), g = picture.at(x, y, 1), b = picture.at(x, y, 2);
      if (std::max({r, g, b}) - std::min({r, g, b}) < 0.04f) {
        ++count[3];
        continue;
      }
      int best = -1;
      double bestDistance = 0.02;  // chromaticity distance at most
      for (int k = 0; k < 3; ++k) {
        const auto& c = levels[k];
        double sum = r + g + b, csum = c[0] + c[1] + c[2];
        double d = std::hypot(r / sum - c[0] / csum, g / sum - c[1] / csum);
        if (d < bestDistance) bestDistance = d, best = k;
      }
      if (best >= 0) ++count[best];
    }
  }
  ASSERT_GT(coveredPixels, 8000);
  // Rings shrink towards the corners: each level covers less than the one before, and the
  // end caps at the corners least.
  EXPECT_GT(count[0], count[1]);
  EXPECT_GT(count[1], count[2]);
  EXPECT_GT(count[2], count[3]);
  EXPECT_GT(count[3], 20);
}

TEST_F(PatchesEndpointTest, CullingLeavesTheImageAsItWas) {
  for (const NamedMesh& shape :
       selectShapes(ownShapes(), {"own_cube", "own_torus_12x8_creased", "own_bumpy_ball_1536"})) {
    std::array<render::Image, 2> pictures;
    std::array<size_t, 2> triangles{};
    for (int cull = 0; cull < 2; ++cull) {
      std::string params =
          std::string(R"({"dicingRate": 2, "cullPatches": )") + (cull ? "true" : "false") + "}";
      HttpResponse r =
          post(port(), "/v1/render", patchesRequest(shape, 256, params, R"(["color"])"));
      ASSERT_EQ(r.status, 200) << shape.name << ": " << r.body.substr(0, 400);
      auto doc = parseJson(r.body);
      pictures[cull] = image(doc["images"], "color");
      triangles[cull] = doc["stats"]["triangles"].GetUint64();
      if (cull) {
        EXPECT_GT(doc["stats"]["patchTable"]["patchesCulled"].GetUint64(), 0u) << shape.name;
      }
    }
    EXPECT_LT(triangles[1], triangles[0]) << shape.name;
    int differing = 0, covered = 0;
    for (int y = 0; y < pictures[0].height; ++y) {
      for (int x = 0; x < pictures[0].width; ++x) {
        covered += pictures[0].at(x, y, 3) > 0.5f;
        float most = 0;
        for (int c = 0; c < 4; ++c) {
          most = std::max(most, std::fabs(pictures[0].at(x, y, c) - pictures[1].at(x, y, c)));
        }
        differing += most > 2.5f / 255;
      }
    }
    EXPECT_LE(differing, covered / 1000) << shape.name;
  }
}

// Pixels where two images differ by more than `tolerance` in any channel.
int differingPixels(const render::Image& a, const render::Image& b, float tolerance) {
  int count = 0;
  for (int y = 0; y < a.height; ++y) {
    for (int x = 0; x < a.width; ++x) {
      float most = 0;
      for (int c = 0; c < a.channels; ++c) {
        most = std::max(most, std::fabs(a.at(x, y, c) - b.at(x, y, c)));
      }
      count += most > tolerance;
    }
  }
  return count;
}

// The same factors diced by tessellation shaders: on llvmpipe the mask is the CPU path's but for
// a few outline pixels, and the colour is as close to the reference's. (Closer along sharp
// creases: the CPU path shares one vertex, hence one normal, between the two sides of a crease;
// the GPU path's patches each keep their own.)
TEST_F(PatchesEndpointTest, GpuTessellatorDrawsTheCpuPicture) {
  for (const NamedMesh& shape : selectShapes(
           ownShapes(), {"own_cube", "own_torus_12x8_creased", "own_cube_sharp_corners",
                         "own_icosahedron_loop", "own_sharp_tetrahedron_loop", "own_pawn_588"})) {
    std::array<render::Image, 2> mask;
    std::array<int, 2> offReference{};
    int covered = 0;
    for (int gpu = 0; gpu < 2; ++gpu) {
      const std::string params =
          std::string(R"({"dicingRate": 1, "tessellator": ")") + (gpu ? "gpu" : "cpu") + R"("})";
      HttpResponse r =
          post(port(), "/v1/render", patchesRequest(shape, 256, params, R"(["color", "mask"])"));
      ASSERT_EQ(r.status, 200) << shape.name << ": " << r.body.substr(0, 400);
      auto doc = parseJson(r.body);
      EXPECT_LE(doc["metrics"]["silhouette"]["hausdorffPx"].GetDouble(), 1.0) << shape.name;
      const auto& table = doc["stats"]["patchTable"];
      EXPECT_STREQ(table["tessellator"].GetString(), gpu ? "gpu" : "cpu");
      EXPECT_EQ(table["gpuDraws"].GetUint64() > 0, gpu == 1) << shape.name;
      mask[gpu] = image(doc["images"], "mask");
      offReference[gpu] = differingPixels(image(doc["images"], "color"),
                                          image(doc["reference"]["images"], "color"), 8.0f / 255);
    }
    for (int y = 0; y < mask[0].height; ++y) {
      for (int x = 0; x < mask[0].width; ++x) covered += mask[0].at(x, y, 0) > 0.5f;
    }
    const int maskOff = differingPixels(mask[0], mask[1], 0.5f);
    std::printf(
        "gpu vs cpu tessellator, %s: %d of %d covered pixels differ in the mask; colour "
        "off the reference by more than 8/255: cpu %d, gpu %d pixels\n",
        shape.name.c_str(), maskOff, covered, offReference[0], offReference[1]);
    EXPECT_GT(covered, 2000) << shape.name;
    EXPECT_LE(maskOff, covered / 1000 + 2) << shape.name;
    EXPECT_LE(offReference[1], offReference[0] + covered / 200) << shape.name;
  }
}

// A torus breathing (its points scaled about the centre by up to 30%) over `frames` frames, as
// the request's "frames" array.
std::string breathingFrames(const render::mesh::ControlMesh& rest, int frames) {
  std::ostringstream out;
  out << "[";
  for (int f = 0; f < frames; ++f) {
    const double scale = 1 + 0.3 * std::sin(2 * std::numbers::pi * f / frames);
    out << (f ? "," : "") << "[";
    for (size_t i = 0; i < rest.points.size(); ++i) {
      const render::Vec3& p = rest.points[i];
      out << (i ? "," : "") << "[" << p.x * scale << "," << p.y * scale << "," << p.z * scale
          << "]";
    }
    out << "]";
  }
  out << "]";
  return out.str();
}

TEST_F(PatchesEndpointTest, ThirtyFramesOfABreathingTorusFromOneTable) {
  const NamedMesh torus = selectShapes(ownShapes(), {"own_torus_12x8_creased"})[0];
  const std::string body = R"({"mesh": )" + requestMeshJson(torus.mesh) +
                           R"(, "camera": {"eye": [0.5, -4, 3], "width": 128, "height": 128},
      "method": "patches", "params": {"dicingRate": 4}, "outputs": ["mask"], "frames": )" +
                           breathingFrames(torus.mesh, 30) + "}";
  HttpResponse r = post(port(), "/v1/render", body);
  ASSERT_EQ(r.status, 200) << r.body.substr(0, 400);
  auto doc = parseJson(r.body);
  ASSERT_TRUE(doc["frames"].IsArray());
  ASSERT_EQ(doc["frames"].Size(), 30u);
  EXPECT_EQ(doc["images"].MemberCount(), 0u);
  EXPECT_EQ(doc["warnings"].Size(), 0u) << r.body.substr(0, 400);
  std::vector<int> covered;
  for (const auto& frame : doc["frames"].GetArray()) {
    EXPECT_GT(frame["triangles"].GetUint64(), 0u);
    render::Image mask = image(frame["images"], "mask");
    int count = 0;
    for (int y = 0; y < mask.height; ++y) {
      for (int x = 0; x < mask.width; ++x) count += mask.at(x, y, 0) > 0.5f;
    }
    covered.push_back(count);
  }
  // The torus grows to frame 7 (scale 1.3) and shrinks to frame 22 (0.7): its area follows.
  EXPECT_GT(covered[7], covered[0] * 1.3);
  EXPECT_LT(covered[22], covered[0] * 0.75);
  EXPECT_NEAR(covered[14], covered[1], covered[0] * 0.05);  // sin(2 pi 14/30) = sin(2 pi/30)
  // The first frame equals a render of the mesh on its own, with nothing culled (later frames
  // reuse its tessellation, and may turn any patch into view).
  const std::string single = R"({"mesh": )" + requestMeshJson(torus.mesh) +
                             R"(, "camera": {"eye": [0.5, -4, 3], "width": 128, "height": 128},
      "method": "patches", "params": {"dicingRate": 4, "cullPatches": false},
      "outputs": ["mask"]})";
  HttpResponse one = post(port(), "/v1/render", single);
  ASSERT_EQ(one.status, 200);
  auto oneDoc = parseJson(one.body);
  EXPECT_EQ(oneDoc["stats"]["triangles"].GetUint64(), doc["frames"][0]["triangles"].GetUint64());

  // Every frame diced anew draws the same picture but for outline pixels; the reused
  // tessellation keeps the first frame's triangle count.
  std::string anew = body;
  anew.replace(anew.find(R"("dicingRate": 4})"), 16,
               R"("dicingRate": 4, "retessellateFrames": true})");
  HttpResponse each = post(port(), "/v1/render", anew);
  ASSERT_EQ(each.status, 200) << each.body.substr(0, 400);
  auto eachDoc = parseJson(each.body);
  ASSERT_EQ(eachDoc["frames"].Size(), 30u);
  for (int f : {0, 7, 22}) {
    EXPECT_EQ(doc["frames"][f]["triangles"].GetUint64(), doc["frames"][0]["triangles"].GetUint64());
    const int differ = differingPixels(image(doc["frames"][f]["images"], "mask"),
                                       image(eachDoc["frames"][f]["images"], "mask"), 0.5f);
    EXPECT_LE(differ, covered[f] / 100 + 5) << "frame " << f;
  }
  EXPECT_NE(eachDoc["frames"][7]["triangles"].GetUint64(),
            eachDoc["frames"][22]["triangles"].GetUint64())
      << "diced anew, a larger frame gets more triangles";
}

TEST_F(PatchesEndpointTest, GpuTessellatorDrawsFramesAndIsNotForDownloads) {
  const NamedMesh torus = selectShapes(ownShapes(), {"own_torus_12x8_creased"})[0];
  const std::string body = R"({"mesh": )" + requestMeshJson(torus.mesh) +
                           R"(, "camera": {"eye": [0.5, -4, 3], "width": 96, "height": 96},
      "method": "patches", "params": {"dicingRate": 4, "tessellator": "gpu"},
      "outputs": ["mask", "patches"], "frames": )" +
                           breathingFrames(torus.mesh, 3) + "}";
  HttpResponse r = post(port(), "/v1/render", body);
  ASSERT_EQ(r.status, 200) << r.body.substr(0, 400);
  auto doc = parseJson(r.body);
  ASSERT_EQ(doc["frames"].Size(), 3u);
  for (const auto& frame : doc["frames"].GetArray()) {
    EXPECT_TRUE(frame["images"].HasMember("patches"));
    EXPECT_GT(frame["triangles"].GetUint64(), 0u);
  }
  HttpResponse download = post(port(), "/v1/tessellate",
                               R"({"mesh": )" + requestMeshJson(torus.mesh) +
                                   R"(, "method": "patches", "params": {"tessellator": "gpu"}})");
  EXPECT_EQ(download.status, 400) << download.body.substr(0, 300);
  EXPECT_EQ(errorField(download), "params.tessellator") << download.body.substr(0, 300);
}

TEST_F(PatchesEndpointTest, BadFramesNameTheField) {
  const NamedMesh cube = selectShapes(ownShapes(), {"own_cube"})[0];
  auto request = [&](const std::string& method, const std::string& frames,
                     const std::string& extra = "") {
    return R"({"mesh": )" + requestMeshJson(cube.mesh) +
           R"(, "camera": {"width": 64, "height": 64}, "method": ")" + method + R"(", "frames": )" +
           frames + extra + "}";
  };
  const std::string two = breathingFrames(cube.mesh, 2);
  struct Case {
    std::string body;
    int status;
    const char* field;
  };
  const std::vector<Case> cases = {
      {request("adaptive", two), 400, "frames"},
      {request("patches", "[]"), 400, "frames"},
      {request("patches", "[[[0, 0, 0]]]"), 400, "frames[0]"},
      {request("patches", "{}"), 400, "frames"},
      {request("patches", two, R"(, "reference": true)"), 400, "reference"},
      {request("patches", breathingFrames(cube.mesh, 121)), 413, "frames"},
  };
  for (const Case& c : cases) {
    HttpResponse r = post(port(), "/v1/render", c.body);
    EXPECT_EQ(r.status, c.status) << r.body.substr(0, 300);
    EXPECT_EQ(errorField(r), c.field) << r.body.substr(0, 300);
  }
}

// Analytic displacement: the displaced patches against the displaced reference, within a pixel
// of its outline; the normals follow the bumps (the colour moves far from the undisplaced
// picture's and stays near the displaced reference's); adaptive draws the same surface.
std::string displacedRequest(const NamedMesh& shape, const std::string& method,
                             const std::string& displacement, const std::string& outputs) {
  render::subdiv::LimitSurface surface(shape.mesh);
  RandomView view = randomViews(surface.bounds(), 1, viewSeed(9, shape.name), 320)[0];
  return R"({"mesh": )" + requestMeshJson(shape.mesh) + R"(, "camera": )" +
         describeCamera(view.camera) + R"(, "method": ")" + method +
         R"(", "params": {"dicingRate": 1}, "reference": true, "outputs": )" + outputs +
         (displacement.empty() ? "" : R"(, "displacement": )" + displacement) + "}";
}

int coveredPixels(const render::Image& mask) {
  int covered = 0;
  for (int y = 0; y < mask.height; ++y) {
    for (int x = 0; x < mask.width; ++x) covered += mask.at(x, y, 0) > 0.5f;
  }
  return covered;
}

TEST_F(PatchesEndpointTest, DisplacedPatchesMatchTheDisplacedReference) {
  const char* bumps = R"({"function": "bumps", "amplitude": 0.02, "frequency": 4})";
  const char* ripples = R"({"function": "ripples", "amplitude": -0.015, "frequency": 3})";
  for (const NamedMesh& shape : selectShapes(
           ownShapes(), {"own_cube", "own_icosahedron_loop", "own_torus_40x25", "own_pawn_588"})) {
    for (const char* displacement : {bumps, ripples}) {
      HttpResponse r =
          post(port(), "/v1/render",
               displacedRequest(shape, "patches", displacement, R"(["color", "mask"])"));
      ASSERT_EQ(r.status, 200) << shape.name << ": " << r.body.substr(0, 400);
      auto doc = parseJson(r.body);
      const double hausdorff = doc["metrics"]["silhouette"]["hausdorffPx"].GetDouble();
      EXPECT_LE(hausdorff, 1.0) << shape.name << " " << displacement;
      const render::Image color = image(doc["images"], "color");
      const int covered = coveredPixels(image(doc["images"], "mask"));
      const int offReference =
          differingPixels(color, image(doc["reference"]["images"], "color"), 16.0f / 255);

      HttpResponse plain =
          post(port(), "/v1/render", displacedRequest(shape, "patches", "", R"(["color"])"));
      ASSERT_EQ(plain.status, 200);
      const int moved =
          differingPixels(color, image(parseJson(plain.body)["images"], "color"), 16.0f / 255);
      std::printf(
          "displaced %s %s: %.3f px, colour off the reference in %d, off the "
          "undisplaced picture in %d of %d covered pixels\n",
          shape.name.c_str(), displacement, hausdorff, offReference, moved, covered);
      // (A sixth: the files hold sRGB, which compresses the lit tones where most of the
      // displaced shading lies; 17-46% of the covered pixels move here.)
      EXPECT_GT(moved, covered / 6) << shape.name << ": the shading follows the displacement";
      EXPECT_LT(offReference, covered / 50) << shape.name << ": and matches the reference's";
    }
    HttpResponse adaptive =
        post(port(), "/v1/render", displacedRequest(shape, "adaptive", bumps, R"(["mask"])"));
    ASSERT_EQ(adaptive.status, 200) << adaptive.body.substr(0, 400);
    EXPECT_LE(parseJson(adaptive.body)["metrics"]["silhouette"]["hausdorffPx"].GetDouble(), 1.0)
        << shape.name << " adaptive";
  }
}

// The GPU tessellator displaces in its evaluation shader (single precision): the same picture
// as the CPU path's but for a few outline pixels, within a pixel of the displaced reference.
TEST_F(PatchesEndpointTest, GpuTessellatorDisplacesAsTheCpuDoes) {
  for (const NamedMesh& shape :
       selectShapes(ownShapes(), {"own_cube", "own_icosahedron_loop", "own_pawn_588"})) {
    std::array<render::Image, 2> mask, color;
    for (int gpu = 0; gpu < 2; ++gpu) {
      std::string body = displacedRequest(
          shape, "patches", R"({"function": "bumps", "amplitude": 0.02})", R"(["color", "mask"])");
      body.replace(
          body.find(R"("dicingRate": 1})"), 16,
          std::string(R"("dicingRate": 1, "tessellator": ")") + (gpu ? "gpu" : "cpu") + R"("})");
      HttpResponse r = post(port(), "/v1/render", body);
      ASSERT_EQ(r.status, 200) << shape.name << ": " << r.body.substr(0, 400);
      auto doc = parseJson(r.body);
      EXPECT_LE(doc["metrics"]["silhouette"]["hausdorffPx"].GetDouble(), 1.0) << shape.name;
      EXPECT_EQ(doc["stats"]["patchTable"]["gpuDraws"].GetUint64() > 0, gpu == 1);
      mask[gpu] = image(doc["images"], "mask");
      color[gpu] = image(doc["images"], "color");
    }
    const int covered = coveredPixels(mask[0]);
    const int maskOff = differingPixels(mask[0], mask[1], 0.5f);
    const int colorOff = differingPixels(color[0], color[1], 16.0f / 255);
    std::printf("displaced gpu vs cpu, %s: mask %d, colour %d of %d covered pixels differ\n",
                shape.name.c_str(), maskOff, colorOff, covered);
    EXPECT_LE(maskOff, covered / 1000 + 2) << shape.name;
    EXPECT_LE(colorOff, covered / 100) << shape.name;
  }
}

TEST_F(PatchesEndpointTest, BadDisplacementNamesTheField) {
  const NamedMesh cube = selectShapes(ownShapes(), {"own_cube"})[0];
  struct Case {
    std::string method, displacement, params;
    const char* field;
  };
  const std::vector<Case> cases = {
      {"patches", R"({"function": "noise"})", "{}", "displacement.function"},
      {"patches", R"({"amplitude": 0.01})", "{}", "displacement.function"},
      {"patches", R"({"function": "bumps", "amplitude": 0.5})", "{}", "displacement.amplitude"},
      {"patches", R"({"function": "bumps", "frequency": 0})", "{}", "displacement.frequency"},
      {"patches", R"({"function": "bumps", "frequency": "high"})", "{}", "displacement.frequency"},
      {"patches", R"("bumps")", "{}", "displacement"},
      {"uniform", R"({"function": "bumps"})", "{}", "method"},
      {"silhouette", R"({"function": "bumps"})", "{}", "method"},
  };
  for (const Case& c : cases) {
    const std::string body = R"({"mesh": )" + requestMeshJson(cube.mesh) +
                             R"(, "camera": {"width": 64, "height": 64}, "method": ")" + c.method +
                             R"(", "params": )" + c.params + R"(, "displacement": )" +
                             c.displacement + "}";
    HttpResponse r = post(port(), "/v1/render", body);
    EXPECT_EQ(r.status, 400) << c.displacement << ": " << r.body.substr(0, 300);
    EXPECT_EQ(errorField(r), c.field) << r.body.substr(0, 300);
  }
}

TEST_F(PatchesEndpointTest, BadParametersNameTheFieldAndTheServerCarriesOn) {
  const NamedMesh cube = selectShapes(ownShapes(), {"own_cube"})[0];
  struct Case {
    std::string params, outputs;
    int status;
    const char* field;
  };
  const std::vector<Case> cases = {
      {R"({"isolation": 9})", "[]", 413, "params.isolation"},
      {R"({"isolation": 0})", "[]", 400, "params.isolation"},
      {R"({"isolation": "deep"})", "[]", 400, "params.isolation"},
      {R"({"tessellator": "magic"})", "[]", 400, "params.tessellator"},
      {R"({"cullPatches": 1})", "[]", 400, "params.cullPatches"},
      {R"({"dicingRate": 0.01})", "[]", 413, "params.dicingRate"},
  };
  for (const Case& c : cases) {
    HttpResponse r = post(port(), "/v1/render", patchesRequest(cube, 64, c.params, c.outputs));
    EXPECT_EQ(r.status, c.status) << c.params << ": " << r.body.substr(0, 300);
    EXPECT_EQ(errorField(r), c.field) << r.body.substr(0, 300);
  }
  HttpResponse ok = post(port(), "/v1/render", patchesRequest(cube, 64, "{}", R"(["color"])"));
  EXPECT_EQ(ok.status, 200);
}

}  // namespace
}  // namespace limn::testing
