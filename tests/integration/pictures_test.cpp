// Pictures through the real server: "antialias" (samples per pixel of the colour outputs, 4 by
// default) blends every outline of the method's picture and of the reference's, one sample per
// pixel blends none, the metrics that do not read colour are the same either way, and a value
// outside 1, 4, 8, 16 is refused naming the field, on every endpoint; "background" transparent
// (straight alpha) or opaque; "imageFormat" jpeg and webp at "imageQuality"; an Accept header
// that prefers an image type gets the picture itself.
#include <gtest/gtest.h>
#include <rapidjson/document.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <sstream>
#include <string>

#include "render/core/shading.h"
#include "render/image/encode.h"
#include "tests/integration/http_client.h"
#include "tests/integration/server_process.h"

namespace limn::testing {
namespace {

// A smooth torus of ring x tube quads, and a creased cube (a sharp outline inside the picture).
std::string torusObj(int ring = 12, int tube = 8) {
  std::ostringstream obj;
  for (int i = 0; i < ring; ++i) {
    for (int j = 0; j < tube; ++j) {
      double a = 2 * M_PI * i / ring, b = 2 * M_PI * j / tube;
      obj << "v " << (1 + 0.35 * std::cos(b)) * std::cos(a) << " "
          << (1 + 0.35 * std::cos(b)) * std::sin(a) << " " << 0.35 * std::sin(b) << "\\n";
    }
  }
  auto id = [&](int i, int j) { return (i % ring) * tube + (j % tube) + 1; };
  for (int i = 0; i < ring; ++i) {
    for (int j = 0; j < tube; ++j) {
      obj << "f " << id(i, j) << " " << id(i + 1, j) << " " << id(i + 1, j + 1) << " "
          << id(i, j + 1) << "\\n";
    }
  }
  return obj.str();
}

const char* kCreasedCube =
    R"(v -1 -1 1\nv 1 -1 1\nv -1 1 1\nv 1 1 1\nv -1 1 -1\nv 1 1 -1\nv -1 -1 -1\nv 1 -1 -1\n)"
    R"(f 1 2 4 3\nf 3 4 6 5\nf 5 6 8 7\nf 7 8 2 1\nf 2 8 6 4\nf 7 1 3 5\nt crease 2/1/0 0 1 2.0\n)"
    R"(t crease 2/1/0 2 3 10\n)";

const char* kTetrahedron = R"(v 1 1 1\nv -1 -1 1\nv -1 1 -1\nv 1 -1 -1\n)"
                           R"(f 1 2 4\nf 1 3 2\nf 1 4 3\nf 2 3 4\n)";

class PicturesServer : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { server_ = new ServerProcess(); }
  static void TearDownTestSuite() {
    EXPECT_EQ(server_->terminate(), 0);
    delete server_;
    server_ = nullptr;
  }
  static int port() { return server_->port(); }

  static std::unique_ptr<rapidjson::Document> answer(const std::string& path,
                                                     const std::string& body, int status = 200) {
    HttpResponse r = post(port(), path, body);
    EXPECT_EQ(r.status, status) << r.body.substr(0, 400);
    auto doc = std::make_unique<rapidjson::Document>();
    doc->Parse(r.body.c_str());
    return doc;
  }

  static ServerProcess* server_;
};
ServerProcess* PicturesServer::server_ = nullptr;

std::string renderBody(const std::string& obj, const std::string& scheme, const std::string& method,
                       const std::string& antialias) {
  return R"({"mesh":{"format":"obj","scheme":")" + scheme + R"(","data":")" + obj +
         R"("},"camera":{"width":160,"height":160,"eye":[2.2,1.6,3.4]},"method":")" + method +
         R"(","params":{"level":2},"outputs":["color","mask"],"reference":true)" + antialias + "}";
}

render::Image imageOf(const rapidjson::Value& images, const char* pass) {
  return render::image::decode(decodeBase64(images[pass]["data"].GetString()));
}

// Pixels of a colour image with alpha strictly between empty and covered.
int partlyCovered(const render::Image& color) {
  int count = 0;
  for (int y = 0; y < color.height; ++y)
    for (int x = 0; x < color.width; ++x) {
      const float a = color.at(x, y, 3);
      count += a > 0.02f && a < 0.98f;
    }
  return count;
}

// Outline pixels of a mask: covered with an uncovered 4-neighbour.
int outlinePixels(const render::Image& mask) {
  int count = 0;
  for (int y = 1; y + 1 < mask.height; ++y)
    for (int x = 1; x + 1 < mask.width; ++x) {
      if (mask.at(x, y) < 0.5f) continue;
      count += mask.at(x - 1, y) < 0.5f || mask.at(x + 1, y) < 0.5f || mask.at(x, y - 1) < 0.5f ||
               mask.at(x, y + 1) < 0.5f;
    }
  return count;
}

TEST_F(PicturesServer, AntialiasedOutlinesBlendAndOneSampleDoesNot) {
  for (const char* method : {"adaptive", "uniform", "silhouette"}) {
    auto smooth = answer("/v1/render", renderBody(torusObj(), "catmull-clark", method, ""));
    auto sharp =
        answer("/v1/render", renderBody(torusObj(), "catmull-clark", method, R"(,"antialias":1)"));
    const int outline = outlinePixels(imageOf((*smooth)["images"], "mask"));
    ASSERT_GT(outline, 100) << method;
    // The default (4 samples): about half the outline's pixels are partly covered, in the
    // method's picture and in the reference's (its rays at the same sample positions).
    EXPECT_GT(partlyCovered(imageOf((*smooth)["images"], "color")), outline / 3) << method;
    EXPECT_GT(partlyCovered(imageOf((*smooth)["reference"]["images"], "color")), outline / 3)
        << method;
    EXPECT_EQ(partlyCovered(imageOf((*sharp)["images"], "color")), 0) << method;
    EXPECT_EQ(partlyCovered(imageOf((*sharp)["reference"]["images"], "color")), 0) << method;
    // The mask is one sample per pixel either way.
    EXPECT_EQ(imageOf((*smooth)["images"], "mask").pixels,
              imageOf((*sharp)["images"], "mask").pixels);
  }
}

// Every metric that does not read colour (outline, coverage, depth, normal, geometry) is the
// same with and without anti-aliasing; the colour difference compares like with like, both
// pictures anti-aliased at the same sample positions, and stays near its one-sample value.
TEST_F(PicturesServer, MetricsThatDoNotReadColourAreTheSameWithAndWithoutAntialiasing) {
  struct Case {
    std::string obj, scheme;
  };
  const Case cases[] = {
      {torusObj(), "catmull-clark"}, {kCreasedCube, "catmull-clark"}, {kTetrahedron, "loop"}};
  for (const Case& c : cases) {
    for (const char* method : {"coarse", "uniform", "adaptive", "silhouette", "patches"}) {
      auto smooth = answer("/v1/render", renderBody(c.obj, c.scheme, method, ""));
      auto sharp = answer("/v1/render", renderBody(c.obj, c.scheme, method, R"(,"antialias":1)"));
      const rapidjson::Value &a = (*smooth)["metrics"], &b = (*sharp)["metrics"];
      for (const char* group : {"silhouette", "depth", "normal", "geometry"}) {
        ASSERT_TRUE(a.HasMember(group)) << group;
        for (const auto& m : a[group].GetObject()) {
          EXPECT_EQ(m.value.GetDouble(), b[group][m.name.GetString()].GetDouble())
              << c.scheme << " " << method << " " << group << "." << m.name.GetString();
        }
      }
      EXPECT_LT(a["image"]["rmse"].GetDouble(), 1.5 * b["image"]["rmse"].GetDouble() + 0.005)
          << c.scheme << " " << method;
    }
  }
}

TEST_F(PicturesServer, CompareAndImplicitDrawAntialiasedToo) {
  auto table = answer("/v1/compare", R"({"mesh":{"format":"obj","data":")" + torusObj() +
                                         R"("},"camera":{"width":128,"height":128},)"
                                         R"("methods":["adaptive"],"outputs":["color"]})");
  const auto& rows = (*table)["rows"];
  ASSERT_EQ(rows.Size(), 1u);
  EXPECT_GT(partlyCovered(imageOf(rows[0]["images"], "color")), 50);
  const std::string field =
      R"({"field":{"iso":0.5,"primitives":[{"type":"metaball","center":[0,0,0],"radius":1},)"
      R"({"type":"metaball","center":[0.8,0.3,0],"radius":0.8}]},)"
      R"("camera":{"width":128,"height":128},"outputs":["color"],"reference":true)";
  auto smooth = answer("/v1/implicit", field + "}");
  auto sharp = answer("/v1/implicit", field + R"(,"antialias":1})");
  EXPECT_GT(partlyCovered(imageOf((*smooth)["images"], "color")), 50);
  EXPECT_GT(partlyCovered(imageOf((*smooth)["reference"]["images"], "color")), 50);
  EXPECT_EQ(partlyCovered(imageOf((*sharp)["images"], "color")), 0);
  EXPECT_EQ((*smooth)["metrics"]["silhouette"]["hausdorffPx"].GetDouble(),
            (*sharp)["metrics"]["silhouette"]["hausdorffPx"].GetDouble());
}

TEST_F(PicturesServer, AntialiasOutsideItsChoicesIsRefusedNamingIt) {
  const std::string cube = R"({"mesh":{"format":"obj","data":")" + std::string(kTetrahedron) +
                           R"(","scheme":"loop"},"camera":{"width":64,"height":64})";
  for (const char* value : {"3", "0", "32", "\"4\"", "4.5"}) {
    for (const std::string& path : {"/v1/render", "/v1/compare"}) {
      const std::string methods = path == "/v1/compare" ? R"(,"methods":["adaptive"])" : "";
      auto refused =
          answer(path, cube + methods + R"(,"antialias":)" + value + "}", /*status=*/400);
      ASSERT_TRUE(refused->HasMember("error")) << path << " " << value;
      EXPECT_STREQ((*refused)["error"]["detail"]["field"].GetString(), "antialias")
          << path << " " << value;
    }
  }
  auto implicit = answer("/v1/implicit",
                         R"({"field":{"primitives":[{"type":"metaball","center":[0,0,0]}]},)"
                         R"("antialias":2})",
                         400);
  EXPECT_STREQ((*implicit)["error"]["detail"]["field"].GetString(), "antialias");
  // 8 and 16 are drawn with as many samples as the device's OpenGL takes, and say so.
  auto sixteen = answer("/v1/render", cube + R"(,"antialias":16,"outputs":["color"]})");
  const bool fewer =
      std::string((*sixteen)["warnings"].Size() ? (*sixteen)["warnings"][0].GetString() : "")
          .find("samples per pixel, the most") != std::string::npos;
  EXPECT_GT(partlyCovered(imageOf((*sixteen)["images"], "color")), 10);
  std::printf("antialias 16 drawn with fewer samples on this device: %s\n", fewer ? "yes" : "no");
}

std::string torusRequest(const std::string& extra) {
  return R"({"mesh":{"format":"obj","data":")" + torusObj() +
         R"("},"camera":{"width":128,"height":128,"eye":[2.2,1.6,3.4]},"method":"adaptive",)"
         R"("outputs":["color","mask"])" +
         extra + "}";
}

// "transparent" (the default) has straight alpha: an edge pixel holds the surface's colour with
// alpha its coverage, so laying it over white gives exactly what "white" answers; an opaque
// colour fills every uncovered pixel with itself at alpha 1.
TEST_F(PicturesServer, BackgroundsAreTransparentWithStraightAlphaOrOpaque) {
  auto transparent = answer("/v1/render", torusRequest(""));
  auto white = answer("/v1/render", torusRequest(R"(,"background":"white")"));
  auto red = answer("/v1/render", torusRequest(R"(,"background":"#ff0000")"));
  const render::Image clear = imageOf((*transparent)["images"], "color");
  const render::Image onWhite = imageOf((*white)["images"], "color");
  const render::Image onRed = imageOf((*red)["images"], "color");
  const render::Image mask = imageOf((*transparent)["images"], "mask");
  int uncovered = 0, edges = 0;
  for (int y = 0; y < clear.height; ++y) {
    for (int x = 0; x < clear.width; ++x) {
      const float a = clear.at(x, y, 3);
      EXPECT_EQ(onWhite.at(x, y, 3), 1.0f);
      EXPECT_EQ(onRed.at(x, y, 3), 1.0f);
      if (a == 0.0f) {
        ++uncovered;
        EXPECT_EQ(mask.at(x, y), 0.0f) << x << "," << y;
        EXPECT_EQ(onRed.at(x, y, 0), 1.0f);
        EXPECT_EQ(onRed.at(x, y, 1), 0.0f);
        continue;
      }
      edges += a < 1.0f;
      // Laid over white in linear light (the files hold sRGB).
      for (int c = 0; c < 3; ++c) {
        const float over = render::shading::linearToSrgb(
            a * render::shading::srgbToLinear(clear.at(x, y, c)) + (1 - a) * 1.0f);
        ASSERT_NEAR(onWhite.at(x, y, c), over, 3.0f / 255) << x << "," << y << " alpha " << a;
      }
    }
  }
  EXPECT_GT(uncovered, 1000);
  EXPECT_GT(edges, 50);
}

TEST_F(PicturesServer, JpegAndWebpComeBackDecodableAtTheirQuality) {
  struct Format {
    const char *name, *mime;
    int channels;
  };
  for (const Format& f : {Format{"jpeg", "image/jpeg", 3}, Format{"webp", "image/webp", 4}}) {
    const std::string format = std::string(R"(,"imageFormat":")") + f.name + "\"";
    auto good = answer("/v1/render", torusRequest(format + R"(,"imageQuality":95)"));
    auto poor = answer("/v1/render", torusRequest(format + R"(,"imageQuality":10)"));
    const rapidjson::Value& color = (*good)["images"]["color"];
    EXPECT_STREQ(color["mime"].GetString(), f.mime);
    const render::Image image = imageOf((*good)["images"], "color");
    EXPECT_EQ(image.width, 128);
    EXPECT_EQ(image.channels, f.channels) << f.name;
    EXPECT_LT(std::string((*poor)["images"]["color"]["data"].GetString()).size(),
              std::string(color["data"].GetString()).size())
        << f.name << ": quality 10 is smaller than 95";
    // Close to the PNG of the same picture (laid over white where JPEG has no alpha).
    auto png = answer("/v1/render", torusRequest(R"(,"background":"white")"));
    const render::Image reference = imageOf((*png)["images"], "color");
    double error = 0;
    for (int y = 0; y < image.height; ++y)
      for (int x = 0; x < image.width; ++x)
        for (int c = 0; c < 3; ++c) {
          const float a = f.channels == 4 ? image.at(x, y, 3) : 1.0f;
          error += std::fabs(a * image.at(x, y, c) + (1 - a) - reference.at(x, y, c));
        }
    EXPECT_LT(error / (3.0 * image.width * image.height), 0.02) << f.name;
  }
  for (const char* bad : {R"(,"imageQuality":0)", R"(,"imageFormat":"gif")",
                          R"(,"background":"#12345")", R"(,"background":"blue")"}) {
    auto refused = answer("/v1/render", torusRequest(bad), 400);
    ASSERT_TRUE(refused->HasMember("error")) << bad;
  }
}

// Accept ranking an image type above JSON: the picture itself, the same pixels as the JSON
// answer's; 406 when the request asks for more than one picture; JSON where JSON ranks higher.
TEST_F(PicturesServer, AcceptAnImageTypeAndTheAnswerIsThePicture) {
  const std::string body = R"({"mesh":{"format":"obj","data":")" + torusObj() +
                           R"("},"camera":{"width":96,"height":96},"method":"adaptive"})";
  auto json = answer("/v1/render", body);
  const render::Image fromJson = imageOf((*json)["images"], "color");
  HttpResponse png = post(port(), "/v1/render", body, {{"Accept", "image/png"}});
  ASSERT_EQ(png.status, 200);
  EXPECT_EQ(png.header("Content-Type"), "image/png");
  EXPECT_EQ(png.header("X-Limn-Pass"), "color");
  const render::Image picture = render::image::decode({png.body.begin(), png.body.end()});
  EXPECT_EQ(picture.pixels, fromJson.pixels);
  HttpResponse webp =
      post(port(), "/v1/render", body, {{"Accept", "application/json;q=0.5, image/webp"}});
  EXPECT_EQ(webp.header("Content-Type"), "image/webp");
  EXPECT_EQ(render::image::decode({webp.body.begin(), webp.body.end()}).width, 96);
  HttpResponse preferJson =
      post(port(), "/v1/render", body, {{"Accept", "application/json, image/png;q=0.2"}});
  EXPECT_EQ(preferJson.header("Content-Type"), "application/json");
  const std::string two = body.substr(0, body.size() - 1) + R"(,"outputs":["color","mask"]})";
  HttpResponse refused = post(port(), "/v1/render", two, {{"Accept", "image/png"}});
  EXPECT_EQ(refused.status, 406);
  EXPECT_EQ(refused.header("Content-Type"), "application/json");
}

// A turntable's views are the renders of the same views: the same masks, the same colours, the
// same metrics; "worst" is the worst of them; the animation is a GIF of every view.
TEST_F(PicturesServer, ATurntablesFramesAreTheRendersOfItsViews) {
  const std::string mesh =
      R"({"format":"obj","scheme":"catmull-clark","data":")" + torusObj() + "\"}";
  auto body = [&](const std::string& camera, const std::string& more,
                  const std::string& outputs = R"(["color","mask"])") {
    return R"({"mesh":)" + mesh + R"(,"camera":)" + camera + R"(,"method":"adaptive","outputs":)" +
           outputs + R"(,"reference":true)" + more + "}";
  };
  auto turntable =
      answer("/v1/render", body(R"({"width":96,"height":96,"orbit":{"azimuthDeg":10}})",
                                R"(,"turntable":{"frames":4,"elevationDeg":25})"));
  const rapidjson::Value& frames = (*turntable)["frames"];
  ASSERT_EQ(frames.Size(), 4u);
  double worstOutline = 0;
  for (rapidjson::SizeType k = 0; k < frames.Size(); ++k) {
    const std::string camera = R"({"width":96,"height":96,"orbit":{"azimuthDeg":)" +
                               std::to_string(10 + 90 * k) + R"(,"elevationDeg":25}})";
    auto alone = answer("/v1/render", body(camera, ""));
    EXPECT_EQ(imageOf(frames[k]["images"], "mask").pixels,
              imageOf((*alone)["images"], "mask").pixels)
        << "view " << k;
    EXPECT_EQ(imageOf(frames[k]["images"], "color").pixels,
              imageOf((*alone)["images"], "color").pixels)
        << "view " << k;
    const double outline = frames[k]["metrics"]["silhouette"]["outlineHausdorffPx"].GetDouble();
    EXPECT_DOUBLE_EQ(outline, (*alone)["metrics"]["silhouette"]["outlineHausdorffPx"].GetDouble());
    worstOutline = std::max(worstOutline, outline);
  }
  EXPECT_DOUBLE_EQ((*turntable)["worst"]["silhouette"]["outlineHausdorffPx"].GetDouble(),
                   worstOutline);
  // The views differ (the torus is not round about +y).
  EXPECT_NE(imageOf(frames[0]["images"], "mask").pixels,
            imageOf(frames[1]["images"], "mask").pixels);

  auto animated = answer("/v1/render", body(R"({"width":64,"height":64})",
                                            R"(,"turntable":{"frames":3})", R"(["turntable"])"));
  ASSERT_TRUE((*animated)["turntable"].HasMember("animation"));
  const std::vector<unsigned char> gif =
      decodeBase64((*animated)["turntable"]["animation"]["data"].GetString());
  ASSERT_GT(gif.size(), 6u);
  EXPECT_EQ(std::string(gif.begin(), gif.begin() + 6), "GIF89a");
  EXPECT_TRUE((*animated)["frames"][0]["images"].ObjectEmpty());  // only the animation was asked

  auto eye = answer("/v1/render", body(R"({"eye":[3,2,3]})", R"(,"turntable":{"frames":3})"), 400);
  EXPECT_STREQ((*eye)["error"]["detail"]["field"].GetString(), "camera.eye");
  answer("/v1/render", body("{}", "", R"(["turntable"])"), 400);
  auto many = answer("/v1/render", body("{}", R"(,"turntable":{"frames":100000})"), 413);
  EXPECT_STREQ((*many)["error"]["detail"]["limit"].GetString(), "maxFrames");
}

}  // namespace
}  // namespace limn::testing
