// POST /v1/implicit through the real server: the sample scenes of configs/implicit within a
// pixel of the ray-cast reference with closed meshes, every polygoniser, seeded random metaball
// scenes the project never tuned on, the OBJ/PLY download, `limn render` with the same request,
// and bad input named field by field (with the server still serving afterwards).
#include <gtest/gtest.h>
#include <rapidjson/document.h>

#include <cmath>
#include <csignal>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

#include "tests/integration/http_client.h"
#include "tests/integration/openapi_check.h"
#include "tests/integration/server_process.h"

namespace limn::testing {
namespace {

rapidjson::Document parse(const std::string& text) {
  rapidjson::Document doc;
  doc.Parse(text.c_str());
  return doc;
}

std::string readScene(const std::string& name) {
  std::ifstream in(std::string(LIMN_SOURCE_DIR) + "/configs/implicit/" + name + ".json");
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// A scene file's request drawn at size x size pixels (the files say 512).
std::string atSize(const std::string& scene, int size) {
  std::string out = scene;
  for (const char* key : {"\"width\": 512", "\"height\": 512"}) {
    const size_t at = out.find(key);
    if (at != std::string::npos) {
      out.replace(
          at, std::string(key).size(),
          std::string(key).substr(0, std::string(key).find(':') + 2) + std::to_string(size));
    }
  }
  return out;
}

// A scene with the polygonizer, outputs and camera replaced.
std::string withPolygonizer(const std::string& scene, const std::string& polygonizer) {
  std::string field = scene.substr(scene.find("\"field\""));
  field = field.substr(0, field.find("\"polygonizer\""));
  // The scenes put "field" first and "polygonizer" next: keep the field's text as it is.
  return "{" + field + R"("polygonizer": )" + polygonizer +
         R"(, "camera": {"orbit": {"azimuthDeg": 30, "elevationDeg": 20}, "width": 256,
            "height": 256}, "outputs": ["color"], "reference": true})";
}

// Random centres, radii and weights, some primitives negative: scenes nobody tuned for.
std::string randomMetaballScene(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> centre(-1.2, 1.2), radius(0.6, 1.4), weight(0.6, 1.6);
  const char* types[] = {"metaball", "soft", "blobby"};
  std::string primitives;
  const int count = 4 + static_cast<int>(rng() % 8);
  for (int i = 0; i < count; ++i) {
    char text[320];
    std::snprintf(
        text, sizeof text,
        R"({"type":"%s","center":[%.4f,%.4f,%.4f],"radius":%.4f,"weight":%.4f,"negative":%s})",
        types[rng() % 3], centre(rng), centre(rng), centre(rng), radius(rng), weight(rng),
        i > 0 && rng() % 4 == 0 ? "true" : "false");
    primitives += (i ? "," : "") + std::string(text);
  }
  return R"({"field":{"iso":0.5,"primitives":[)" + primitives +
         R"(]},"camera":{"width":256,"height":256},"outputs":["color"],"reference":true})";
}

class ImplicitServer : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    // A generous time limit: under the sanitizers (scripts/sanitize.sh) a render with its
    // reference takes several times longer.
    server_ = new ServerProcess(ServerProcess::withConfig(
        R"({"workers": 2, "requestTimeoutMs": 900000,
            "limits": {"maxPrimitives": 16, "maxResolution": 200, "maxExpressionLength": 64}})"));
  }
  static void TearDownTestSuite() {
    EXPECT_EQ(server_->terminate(SIGTERM), 0);
    delete server_;
    server_ = nullptr;
  }
  static int port() { return server_->port(); }

  // POSTs and expects 200 with a closed mesh within `bound` px of the reference.
  static rapidjson::Document renderClosed(const std::string& body, double bound,
                                          const std::string& what) {
    HttpResponse r = post(port(), "/v1/implicit", body);
    EXPECT_EQ(r.status, 200) << what << ": " << r.body.substr(0, 400);
    rapidjson::Document doc = parse(r.body);
    if (r.status != 200 || !doc.IsObject() || !doc.HasMember("stats")) return doc;
    const auto& stats = doc["stats"];
    EXPECT_TRUE(stats["closed"].GetBool()) << what;
    EXPECT_EQ(stats["implicit"]["boundaryEdges"].GetUint64(), 0u) << what;
    EXPECT_EQ(stats["implicit"]["misorientedEdges"].GetUint64(), 0u) << what;
    EXPECT_GT(stats["triangles"].GetUint64(), 100u) << what;
    const auto& silhouette = doc["metrics"]["silhouette"];
    EXPECT_LE(silhouette["hausdorffPx"].GetDouble(), bound) << what;
    EXPECT_LE(silhouette["outlineHausdorffPx"].GetDouble(), bound) << what;
    EXPECT_GT(silhouette["iou"].GetDouble(), 0.98) << what;
    EXPECT_LT(doc["metrics"]["geometry"]["relMaxDist"].GetDouble(), 0.01) << what;
    EXPECT_TRUE(doc["images"].HasMember("color")) << what;
    EXPECT_TRUE(doc["reference"]["images"].HasMember("color")) << what;
    return doc;
  }

  static ServerProcess* server_;
};
ServerProcess* ImplicitServer::server_ = nullptr;

TEST_F(ImplicitServer, SampleScenesAreWithinAPixelOfTheReference) {
  for (const char* name : {"sphere_bite", "metaball_figure", "sphere_cylinder_cut"}) {
    rapidjson::Document doc = renderClosed(atSize(readScene(name), 256), 1.0, name);
    if (!doc.IsObject() || !doc.HasMember("stats")) continue;
    EXPECT_GT(doc["timings"]["referenceMs"].GetDouble(), 0.0) << name;
    EXPECT_GT(doc["stats"]["implicit"]["primitives"].GetUint64(), 1u) << name;
  }
}

TEST_F(ImplicitServer, EveryPolygonizerGivesAClosedAccurateMesh) {
  const std::string scene = readScene("metaball_figure");
  size_t marchingCubesTriangles = 0;
  for (const char* method : {"marching-cubes", "tracker", "octree", "adaptive"}) {
    rapidjson::Document doc = renderClosed(
        withPolygonizer(scene, std::string(R"({"method": ")") + method + R"(", "resolution": 96})"),
        1.0, method);
    if (!doc.IsObject() || !doc.HasMember("stats")) continue;
    EXPECT_STREQ(doc["stats"]["implicit"]["polygonizer"].GetString(), method);
    const size_t triangles = doc["stats"]["triangles"].GetUint64();
    if (std::string(method) == "marching-cubes") marchingCubesTriangles = triangles;
    if (std::string(method) == "tracker") {
      EXPECT_EQ(triangles, marchingCubesTriangles);
    }
    if (std::string(method) == "octree") {
      EXPECT_LT(triangles, marchingCubesTriangles);
    }
  }
}

TEST_F(ImplicitServer, RandomMetaballScenesAreWithinAPixel) {
  for (unsigned seed = 1; seed <= 8; ++seed) {
    renderClosed(randomMetaballScene(seed), 1.0, "random scene " + std::to_string(seed));
  }
}

TEST_F(ImplicitServer, DownloadsTheMeshAsObjOrPly) {
  const std::string body = readScene("sphere_bite");
  HttpResponse obj = post(port(), "/v1/implicit", body, {{"Accept", "text/plain"}});
  ASSERT_EQ(obj.status, 200) << obj.body.substr(0, 300);
  EXPECT_EQ(obj.header("X-Limn-Closed"), "true");
  size_t vertices = 0, faces = 0;
  std::istringstream lines(obj.body);
  for (std::string line; std::getline(lines, line);) {
    vertices += line.rfind("v ", 0) == 0;
    faces += line.rfind("f ", 0) == 0;
  }
  EXPECT_EQ(std::to_string(faces), obj.header("X-Limn-Triangles"));
  EXPECT_EQ(std::to_string(vertices), obj.header("X-Limn-Vertices"));
  HttpResponse ply = post(port(), "/v1/implicit", body, {{"Accept", "application/x-ply"}});
  ASSERT_EQ(ply.status, 200);
  EXPECT_EQ(ply.body.rfind("ply\n", 0), 0u);
  EXPECT_EQ(ply.header("X-Limn-Triangles"), obj.header("X-Limn-Triangles"));
  EXPECT_EQ(post(port(), "/v1/implicit", body, {{"Accept", "image/png"}}).status, 406);
}

TEST_F(ImplicitServer, NamesWhatIsWrongWithABadScene) {
  const std::string sphere = R"({"type":"soft","radius":2})";
  auto scene = [](const std::string& primitives, const std::string& rest = "") {
    return R"({"field":{"primitives":[)" + primitives + "]}" + rest + "}";
  };
  struct Case {
    std::string body;
    int status;
    std::string field;  // the error detail names it
  };
  const Case cases[] = {
      {scene(R"({"type":"teapot"})"), 400, "field.primitives[0].type"},
      {scene(R"({"type":"soft","radius":1e999})"), 400, ""},
      {scene(R"({"type":"soft","radius":-1})"), 400, "field.primitives[0].radius"},
      {scene(R"({"type":"soft","center":[0,"x",0]})"), 400, "field.primitives[0].center"},
      {scene(sphere + R"(,{"type":"expression","expression":"x +* 2","negative":true})"), 400,
       "field.primitives[1].expression"},
      {scene(sphere + R"(,{"type":"expression","expression":"x + w","negative":true})"), 400,
       "field.primitives[1].expression"},
      {scene(sphere + R"j(,{"type":"expression","expression":"fopen(x)","negative":true})j"), 400,
       "field.primitives[1].expression"},
      {scene(sphere + R"(,{"type":"expression","expression":")" + std::string(80, 'x') +
             R"(","negative":true})"),
       413, ""},
      {scene(sphere, R"(,"polygonizer":{"resolution":500})"), 413, ""},
      {scene(sphere, R"(,"polygonizer":{"method":"dual-contouring"})"), 400, "polygonizer.method"},
      {scene(sphere, R"(,"polygonizer":{"flatness":2})"), 400, "polygonizer.flatness"},
      {scene(R"({"type":"soft","negative":true})"), 400, "field.primitives"},
      {scene(R"({"type":"expression","expression":"x^2+y^2-1"})"), 400,
       "field.primitives[0].bounds"},
      {R"({"field":{"iso":-1,"primitives":[)" + sphere + "]}}", 400, "field.iso"},
      {R"({"polygonizer":{}})", 400, "field"},
  };
  std::string many;
  for (int i = 0; i < 17; ++i) many += (i ? "," : "") + sphere;
  std::vector<Case> all(std::begin(cases), std::end(cases));
  all.push_back({scene(many), 413, ""});
  for (const Case& c : all) {
    HttpResponse r = post(port(), "/v1/implicit", c.body);
    EXPECT_EQ(r.status, c.status) << c.body << "\n" << r.body;
    if (!c.field.empty()) {
      EXPECT_NE(r.body.find("\"" + c.field + "\""), std::string::npos) << c.body << "\n" << r.body;
    }
  }
  // Still serving.
  EXPECT_EQ(post(port(), "/v1/implicit", scene(sphere)).status, 200);
}

TEST_F(ImplicitServer, AnswersMatchTheOpenApiDocument) {
  const std::vector<ApiExchange> exchanges = {
      {"POST", "/v1/implicit", "", readScene("sphere_bite")},
      {"POST", "/v1/implicit", "", readScene("sphere_bite"), {{"Accept", "text/plain"}}},
      {"POST", "/v1/implicit", "", R"({"field":{"primitives":[{"type":"teapot"}]}})"},
      {"POST",
       "/v1/implicit",
       "",
       R"({"field":{"primitives":[{"type":"soft"}]}})",
       {{"Accept", "image/png"}}},
      {"POST", "/v1/implicit", "",
       R"({"field":{"primitives":[{"type":"soft"}]},"polygonizer":{"resolution":900}})"},
  };
  OpenApiCheck check = checkAgainstOpenApi(port(), exchanges);
  EXPECT_EQ(check.status, 0) << check.output;
  EXPECT_EQ(check.statuses, (std::set<int>{200, 400, 406, 413}));
}

}  // namespace
}  // namespace limn::testing
