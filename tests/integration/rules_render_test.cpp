// limn's own subdivision rules and the cage overlay through the real server: method "uniform"
// with params.engine "masks" and "factored" answers what "opensubdiv" answers, pushToLimit puts
// the vertices on the limit surface, outputs "cage" draws the control cage over the surface,
// flat shading shows facets, and the new fields' errors name the field.
#include <gtest/gtest.h>
#include <rapidjson/document.h>
#include <rapidjson/stringbuffer.h>
#include <rapidjson/writer.h>

#include <cmath>
#include <csignal>
#include <memory>
#include <set>
#include <sstream>
#include <string>

#include "render/image/encode.h"
#include "tests/integration/http_client.h"
#include "tests/integration/server_process.h"

namespace limn::testing {
namespace {

const char* kCubeObj =
    "v -1 -1 1\nv 1 -1 1\nv -1 1 1\nv 1 1 1\nv -1 1 -1\nv 1 1 -1\nv -1 -1 -1\nv 1 -1 -1\n"
    "f 1 2 4 3\nf 3 4 6 5\nf 5 6 8 7\nf 7 8 2 1\nf 2 8 6 4\nf 7 1 3 5\n";

const char* kTetrahedronObj =
    "v 1 1 1\nv -1 -1 1\nv -1 1 -1\nv 1 -1 -1\nf 1 2 4\nf 1 3 2\nf 1 4 3\nf 2 3 4\n";

// A smooth torus of ring x tube quads (no creases: every engine takes it).
std::string torusObj(int ring = 16, int tube = 10) {
  std::ostringstream obj;
  for (int i = 0; i < ring; ++i) {
    for (int j = 0; j < tube; ++j) {
      double a = 2 * M_PI * i / ring, b = 2 * M_PI * j / tube;
      obj << "v " << (1 + 0.35 * std::cos(b)) * std::cos(a) << " "
          << (1 + 0.35 * std::cos(b)) * std::sin(a) << " " << 0.35 * std::sin(b) << "\n";
    }
  }
  auto id = [&](int i, int j) { return (i % ring) * tube + (j % tube) + 1; };
  for (int i = 0; i < ring; ++i) {
    for (int j = 0; j < tube; ++j) {
      obj << "f " << id(i, j) << " " << id(i + 1, j) << " " << id(i + 1, j + 1) << " "
          << id(i, j + 1) << "\n";
    }
  }
  return obj.str();
}

// A request body; `params` and `outputs` are JSON fragments.
std::string body(const std::string& obj, const std::string& scheme, const std::string& method,
                 const std::string& params, const std::string& outputs, bool reference,
                 int size = 192, const std::string& shading = "smooth") {
  rapidjson::StringBuffer data;
  {
    rapidjson::Writer<rapidjson::StringBuffer> writer(data);
    writer.String(obj.c_str(), static_cast<rapidjson::SizeType>(obj.size()));
  }
  std::ostringstream out;
  out << R"({"mesh":{"format":"obj","scheme":")" << scheme << R"(","data":)" << data.GetString()
      << R"(},"camera":{"width":)" << size << R"(,"height":)" << size
      << R"(,"eye":[2.2,1.6,3.4]},"method":")" << method << R"(","params":)" << params
      << R"(,"shading":")" << shading << R"(","outputs":)" << outputs << R"(,"reference":)"
      << (reference ? "true" : "false") << "}";
  return out.str();
}

class RulesServer : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    server_ = new ServerProcess(ServerProcess::withConfig(R"({"workers": 2})"));
  }
  static void TearDownTestSuite() {
    EXPECT_EQ(server_->terminate(SIGTERM), 0);
    delete server_;
    server_ = nullptr;
  }

  struct Answer {
    int status = 0;
    rapidjson::Document json;
    std::string text;
  };
  static std::unique_ptr<Answer> render(const std::string& request) {
    HttpResponse response = post(server_->port(), "/v1/render", request);
    auto answer = std::make_unique<Answer>();
    answer->status = response.status;
    answer->text = response.body;
    answer->json.Parse(response.body.c_str());
    return answer;
  }
  static render::Image image(const Answer& answer, const char* pass) {
    const auto& encoded = answer.json["images"][pass];
    return render::image::decode(decodeBase64(encoded["data"].GetString()));
  }

  static ServerProcess* server_;
};
ServerProcess* RulesServer::server_ = nullptr;

double hausdorffPx(const rapidjson::Document& json) {
  return json["metrics"]["silhouette"]["hausdorffPx"].GetDouble();
}

// Pixels where two images of the same size differ by more than `tolerance` in any channel.
size_t differingPixels(const render::Image& a, const render::Image& b,
                       float tolerance = 2.5f / 255) {
  size_t count = 0;
  for (int y = 0; y < a.height; ++y) {
    for (int x = 0; x < a.width; ++x) {
      for (int c = 0; c < a.channels; ++c) {
        if (std::fabs(a.at(x, y, c) - b.at(x, y, c)) > tolerance) {
          ++count;
          break;
        }
      }
    }
  }
  return count;
}

TEST_F(RulesServer, OwnEnginesAnswerWhatOpenSubdivAnswers) {
  struct Case {
    std::string obj, scheme;
    std::vector<std::string> engines;
  };
  const Case cases[] = {{torusObj(), "catmull-clark", {"masks", "factored"}},
                        {kTetrahedronObj, "loop", {"masks"}}};
  for (const Case& c : cases) {
    auto far = render(body(c.obj, c.scheme, "uniform", R"({"level":3})", R"(["color"])", true));
    ASSERT_EQ(far->status, 200) << far->text.substr(0, 300);
    const render::Image farColor = image(*far, "color");
    for (const std::string& engine : c.engines) {
      auto own = render(body(c.obj, c.scheme, "uniform",
                             R"({"level":3,"engine":")" + engine + "\"}", R"(["color"])", true));
      ASSERT_EQ(own->status, 200) << engine << ": " << own->text.substr(0, 300);
      EXPECT_EQ(own->json["stats"]["triangles"].GetInt64(),
                far->json["stats"]["triangles"].GetInt64())
          << engine;
      EXPECT_NEAR(hausdorffPx(own->json), hausdorffPx(far->json), 0.05) << engine;
      // The same mesh with the same normals: the same picture, give or take rounding.
      const render::Image color = image(*own, "color");
      ASSERT_EQ(color.width, farColor.width);
      EXPECT_LE(differingPixels(color, farColor), size_t(color.width * color.height / 1000))
          << engine;
    }
  }
}

TEST_F(RulesServer, PushToLimitPutsEveryVertexOnTheLimit) {
  for (const char* engine : {"opensubdiv", "masks"}) {
    const std::string params = std::string(R"({"level":2,"engine":")") + engine + "\"";
    auto refined = render(body(kCubeObj, "catmull-clark", "uniform", params + "}", "[]", true, 96));
    auto pushed = render(body(kCubeObj, "catmull-clark", "uniform",
                              params + R"(,"pushToLimit":true})", "[]", true, 96));
    ASSERT_EQ(refined->status, 200) << refined->text.substr(0, 300);
    ASSERT_EQ(pushed->status, 200) << pushed->text.substr(0, 300);
    // The geometry metric compares uniform's vertices with their own limit positions.
    EXPECT_GT(refined->json["metrics"]["geometry"]["relMaxDist"].GetDouble(), 1e-3) << engine;
    EXPECT_LT(pushed->json["metrics"]["geometry"]["relMaxDist"].GetDouble(), 1e-6) << engine;
    // On the limit, the outline is closer to the exact one.
    EXPECT_LT(hausdorffPx(pushed->json), hausdorffPx(refined->json)) << engine;
  }
}

TEST_F(RulesServer, CageIsDrawnOverTheSurface) {
  auto answer = render(body(kCubeObj, "catmull-clark", "uniform", R"({"level":3})",
                            R"(["color","cage"])", false, 256));
  ASSERT_EQ(answer->status, 200) << answer->text.substr(0, 300);
  ASSERT_TRUE(answer->json["images"].HasMember("cage"));
  EXPECT_STREQ(answer->json["images"]["cage"]["mime"].GetString(), "image/png");
  const render::Image color = image(*answer, "color"), cage = image(*answer, "cage");
  ASSERT_EQ(cage.width, color.width);
  ASSERT_EQ(cage.height, color.height);
  // The cage's edges differ from the colour pass, everything else is the same picture.
  size_t total = static_cast<size_t>(color.width) * color.height;
  size_t differing = 0;
  double red = 0, blue = 0, brightness = 0;
  for (int y = 0; y < color.height; ++y) {
    for (int x = 0; x < color.width; ++x) {
      bool differs = false;
      for (int c = 0; c < 3; ++c)
        differs = differs || std::fabs(cage.at(x, y, c) - color.at(x, y, c)) > 0.02f;
      if (!differs) continue;
      ++differing;
      red += cage.at(x, y, 0);
      blue += cage.at(x, y, 2);
      brightness += (cage.at(x, y, 0) + cage.at(x, y, 1) + cage.at(x, y, 2)) / 3;
    }
  }
  EXPECT_GT(differing, size_t(1000)) << "the cage is not visible";
  EXPECT_LT(differing, total / 5) << "the cage covers too much";
  ASSERT_GT(differing, 0u);
  // Where they differ, the cage pass shows the dark blue of the cage lines.
  EXPECT_LT(brightness / differing, 0.3);
  EXPECT_GT(blue / differing, red / differing);
  RecordProperty("cagePixels", std::to_string(differing));

  // The reference has no cage; method limit draws none.
  auto limit =
      render(body(kCubeObj, "catmull-clark", "limit", "{}", R"(["color","cage"])", false, 64));
  EXPECT_EQ(limit->status, 400);
  EXPECT_NE(limit->text.find("cage"), std::string::npos);
}

TEST_F(RulesServer, FlatShadingShowsFacets) {
  // The normal pass of a level-1 cube: one normal per triangle with flat shading (48 triangles,
  // fewer visible), interpolated limit normals with smooth shading.
  auto distinctNormals = [&](const std::string& shading) {
    auto answer = render(body(kCubeObj, "catmull-clark", "uniform", R"({"level":1})",
                              R"(["normal","mask"])", false, 128, shading));
    EXPECT_EQ(answer->status, 200) << answer->text.substr(0, 300);
    const render::Image normal = image(*answer, "normal"), mask = image(*answer, "mask");
    std::set<std::tuple<int, int, int>> seen;
    for (int y = 0; y < normal.height; ++y) {
      for (int x = 0; x < normal.width; ++x) {
        if (mask.at(x, y) < 0.5f) continue;
        seen.insert({static_cast<int>(normal.at(x, y, 0) * 255 + 0.5f),
                     static_cast<int>(normal.at(x, y, 1) * 255 + 0.5f),
                     static_cast<int>(normal.at(x, y, 2) * 255 + 0.5f)});
      }
    }
    return seen.size();
  };
  size_t flat = distinctNormals("flat"), smooth = distinctNormals("smooth");
  EXPECT_LE(flat, 48u * 3) << "flat shading should give one normal per triangle (x rounding)";
  EXPECT_GT(smooth, 10 * flat);
}

TEST_F(RulesServer, EngineErrorsNameTheField) {
  auto unknown = render(body(kCubeObj, "catmull-clark", "uniform", R"({"engine":"magic"})",
                             R"(["color"])", false, 32));
  EXPECT_EQ(unknown->status, 400);
  EXPECT_NE(unknown->text.find("params.engine"), std::string::npos) << unknown->text;
  EXPECT_NE(unknown->text.find("\\\"masks\\\""), std::string::npos) << "lists the valid names";

  auto loop = render(body(kTetrahedronObj, "loop", "uniform", R"({"engine":"factored"})",
                          R"(["color"])", false, 32));
  EXPECT_EQ(loop->status, 400);
  EXPECT_NE(loop->text.find("params.engine"), std::string::npos) << loop->text;

  auto push = render(body(kCubeObj, "catmull-clark", "uniform", R"({"pushToLimit":"yes"})",
                          R"(["color"])", false, 32));
  EXPECT_EQ(push->status, 400);
  EXPECT_NE(push->text.find("params.pushToLimit"), std::string::npos) << push->text;

  // Three faces on one edge: OpenSubdiv takes it, limn's own rules answer 422 naming the edge.
  std::string fin = std::string(kCubeObj) + "v 0 0 3\nf 1 2 9\n";
  auto nonManifold = render(body(fin, "catmull-clark", "uniform", R"({"level":1,"engine":"masks"})",
                                 R"(["color"])", false, 32));
  EXPECT_EQ(nonManifold->status, 422) << nonManifold->text;
  EXPECT_NE(nonManifold->text.find("edge 0-1"), std::string::npos) << nonManifold->text;
  auto farTakesIt =
      render(body(fin, "catmull-clark", "uniform", R"({"level":1})", R"(["color"])", false, 32));
  EXPECT_EQ(farTakesIt->status, 200) << farTakesIt->text.substr(0, 300);

  // Other methods ignore the engine, with a warning.
  auto coarse = render(body(kCubeObj, "catmull-clark", "coarse", R"({"engine":"masks"})",
                            R"(["color"])", false, 32));
  ASSERT_EQ(coarse->status, 200);
  EXPECT_NE(coarse->text.find("params.engine"), std::string::npos) << "warns";
}

}  // namespace
}  // namespace limn::testing
