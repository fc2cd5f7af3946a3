// What the web page relies on, through the real server: the page and the examples served by
// limn itself, meshes uploaded once and rendered by id (POST /v1/meshes), the orbit camera,
// and the diff output against the reference. Every example the project ships renders.
#include <gtest/gtest.h>
#include <rapidjson/document.h>
#include <rapidjson/stringbuffer.h>
#include <rapidjson/writer.h>
#include <sys/stat.h>

#include <array>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <memory>
#include <set>
#include <string>
#include <thread>

#include "render/image/encode.h"
#include "tests/integration/http_client.h"
#include "tests/integration/openapi_check.h"
#include "tests/integration/server_process.h"

namespace limn::testing {
namespace {

std::string jsonString(const std::string& text) {
  rapidjson::StringBuffer out;
  rapidjson::Writer<rapidjson::StringBuffer> writer(out);
  writer.String(text.c_str(), static_cast<rapidjson::SizeType>(text.size()));
  return out.GetString();
}

std::string objMesh(const std::string& obj, const std::string& scheme = "catmull-clark") {
  return R"({"format":"obj","scheme":")" + scheme + R"(","data":)" + jsonString(obj) + "}";
}

rapidjson::Document parse(const std::string& text) {
  rapidjson::Document doc;
  doc.Parse(text.c_str());
  return doc;
}

class WebServer : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    // A small mesh cache, so that eviction can be seen.
    server_ =
        new ServerProcess(ServerProcess::withConfig(R"({"workers": 2, "meshCacheBytes": 40000})"));
  }
  static void TearDownTestSuite() {
    EXPECT_EQ(server_->terminate(SIGTERM), 0);
    delete server_;
    server_ = nullptr;
  }
  static int port() { return server_->port(); }
  static std::string example(const std::string& name) {
    HttpResponse r = get(port(), "/examples/" + name);
    EXPECT_EQ(r.status, 200) << name;
    return r.body;
  }
  static std::string upload(const std::string& meshJson) {
    HttpResponse r = post(port(), "/v1/meshes", R"({"mesh":)" + meshJson + "}");
    EXPECT_EQ(r.status, 200) << r.body.substr(0, 300);
    rapidjson::Document doc = parse(r.body);
    return doc.HasMember("id") ? doc["id"].GetString() : "";
  }

  static ServerProcess* server_;
};
ServerProcess* WebServer::server_ = nullptr;

TEST_F(WebServer, ServesThePageItsScriptsAndStyle) {
  HttpResponse page = get(port(), "/");
  ASSERT_EQ(page.status, 200);
  EXPECT_EQ(page.header("Content-Type"), "text/html; charset=utf-8");
  EXPECT_NE(page.body.find(R"(<script type="module" src="/app.js">)"), std::string::npos);
  EXPECT_EQ(get(port(), "/index.html").body, page.body);
  for (const char* path :
       {"/app.js", "/api.js", "/glview.js", "/layout.js", "/metrics.js", "/diff.js"}) {
    HttpResponse script = get(port(), path);
    EXPECT_EQ(script.status, 200) << path;
    EXPECT_EQ(script.header("Content-Type"), "text/javascript; charset=utf-8") << path;
  }
  HttpResponse style = get(port(), "/style.css");
  EXPECT_EQ(style.status, 200);
  EXPECT_EQ(style.header("Content-Type"), "text/css; charset=utf-8");
  // Nothing the page loads comes from another origin (it works offline).
  for (const char* path : {"/", "/app.js", "/api.js", "/glview.js", "/layout.js", "/metrics.js",
                           "/diff.js", "/style.css"}) {
    EXPECT_EQ(get(port(), path).body.find("://"), std::string::npos) << path;
  }
  HttpResponse wrongMethod = post(port(), "/", "{}");
  EXPECT_EQ(wrongMethod.status, 405);
  EXPECT_EQ(wrongMethod.header("Allow"), "GET");
  EXPECT_EQ(get(port(), "/nothing.js").status, 404);
}

TEST_F(WebServer, OpenApiDocumentDescribesWhatThePageUses) {
  rapidjson::Document doc = parse(get(port(), "/openapi.json").body);
  for (const char* path : {"/", "/examples", "/examples/{name}", "/v1/meshes"}) {
    EXPECT_TRUE(doc["paths"].HasMember(path)) << path;
  }
  const auto& schemas = doc["components"]["schemas"];
  EXPECT_TRUE(schemas["Camera"]["properties"].HasMember("orbit"));
  EXPECT_TRUE(schemas["Images"]["properties"].HasMember("diff"));
  EXPECT_TRUE(schemas["Metrics"]["properties"]["image"]["properties"].HasMember("diffScale"));
}

// The new routes' real answers against the document, as server_test does for the others
// (tests/integration/check_openapi.py: declared statuses and media types, strict schemas).
TEST_F(WebServer, RealAnswersMatchTheOpenApiDocument) {
  const std::string cube = objMesh(example("cube"));
  const std::string id = upload(cube);
  const std::string big =
      objMesh("v 0 0 0\nv 1 0 0\nv 0 1 0\n" + std::string(40000, '#') + "\nf 1 2 3\n" + [] {
        std::string v;
        for (int i = 0; i < 2000; ++i) v += "v 1 2 3\n";
        return v;
      }());
  const std::vector<ApiExchange> exchanges = {
      {"GET", "/", "/", ""},
      {"GET", "/examples", "/examples", ""},
      {"GET", "/examples/pawn", "/examples/{name}", ""},
      {"GET", "/examples/teapot", "/examples/{name}", ""},
      {"POST", "/examples", "/examples", ""},
      {"POST", "/v1/meshes", "/v1/meshes", R"({"mesh":)" + cube + "}"},
      {"POST", "/v1/meshes", "/v1/meshes", R"({"mesh":{"id":"x"}})"},
      {"POST", "/v1/meshes", "/v1/meshes", R"({"mesh":)" + objMesh("v 0 0 0\nf 1 2 3\n") + "}"},
      {"POST", "/v1/meshes", "/v1/meshes", R"({"mesh":)" + big + "}"},
      {"GET", "/v1/meshes", "/v1/meshes", ""},
      {"POST", "/v1/render", "/v1/render",
       R"({"mesh":{"id":")" + id +
           R"("},"method":"uniform","outputs":["color","diff"],"reference":true,)"
           R"("camera":{"orbit":{"azimuthDeg":30,"elevationDeg":20,"distance":4},"width":48,"height":48}})"},
      {"POST", "/v1/render", "/v1/render", R"({"mesh":{"id":"feed"}})"},
      {"POST", "/v1/tessellate", "/v1/tessellate", R"({"mesh":{"id":")" + id + R"("}})"},
      {"POST",
       "/v1/tessellate",
       "/v1/tessellate",
       R"({"mesh":{"id":")" + id + R"("}})",
       {{"Accept", "application/x-ply"}}},
      {"POST",
       "/v1/tessellate",
       "/v1/tessellate",
       R"({"mesh":{"id":")" + id + R"("}})",
       {{"Accept", "text/plain"}}},
      {"POST",
       "/v1/tessellate",
       "/v1/tessellate",
       R"({"mesh":{"id":")" + id + R"("}})",
       {{"Accept", "image/png"}}},
      {"POST", "/v1/tessellate", "/v1/tessellate",
       R"({"mesh":{"id":")" + id + R"("},"method":"limit"})"},
      {"POST", "/v1/silhouette", "/v1/silhouette", R"({"mesh":{"id":"feed"}})"},
  };
  OpenApiCheck check = checkAgainstOpenApi(port(), exchanges);
  EXPECT_EQ(check.status, 0) << check.output;
  EXPECT_EQ(check.statuses, (std::set<int>{200, 400, 404, 405, 406, 413, 422}))
      << "the exchanges cover these";
}

TEST_F(WebServer, ListsAndServesTheExamples) {
  HttpResponse list = get(port(), "/examples");
  ASSERT_EQ(list.status, 200);
  EXPECT_EQ(list.header("Content-Type"), "application/json");
  rapidjson::Document doc = parse(list.body);
  ASSERT_TRUE(doc.IsArray());
  std::set<std::string> names;
  for (const auto& e : doc.GetArray()) {
    names.insert(e["name"].GetString());
    EXPECT_TRUE(e.HasMember("title") && e.HasMember("scheme"));
  }
  EXPECT_EQ(names, (std::set<std::string>{"cube", "torus_creased", "icosahedron", "pawn", "grid"}));
  std::string cube = example("cube");
  EXPECT_EQ(get(port(), "/examples/cube").header("Content-Type"), "text/plain; charset=utf-8");
  size_t vertices = 0;
  for (size_t at = cube.find("\nv "); at != std::string::npos; at = cube.find("\nv ", at + 1)) {
    ++vertices;
  }
  EXPECT_EQ(vertices, 8u);
  EXPECT_EQ(get(port(), "/examples/teapot").status, 404);
}

// Each shipped example renders with every method the page offers, with the counts its file
// says, and covers a fair part of the picture from the page's opening view.
TEST_F(WebServer, EveryExampleRenders) {
  rapidjson::Document list = parse(get(port(), "/examples").body);
  for (const auto& e : list.GetArray()) {
    const std::string name = e["name"].GetString(), scheme = e["scheme"].GetString();
    const std::string id = upload(objMesh(example(name), scheme));
    ASSERT_FALSE(id.empty()) << name;
    for (const char* method : {"coarse", "uniform", "adaptive", "silhouette"}) {
      HttpResponse r = post(port(), "/v1/render",
                            R"({"mesh":{"id":")" + id + R"("},"method":")" + method +
                                R"(","params":{"level":2},"outputs":["color","mask"],)"
                                R"("camera":{"orbit":{"azimuthDeg":30,"elevationDeg":20},)"
                                R"("width":128,"height":128}})");
      ASSERT_EQ(r.status, 200) << name << " " << method << ": " << r.body.substr(0, 300);
      rapidjson::Document doc = parse(r.body);
      EXPECT_GT(doc["stats"]["triangles"].GetInt64(), 0) << name << " " << method;
      render::Image mask =
          render::image::decode(decodeBase64(doc["images"]["mask"]["data"].GetString()));
      double covered = 0;
      for (float v : mask.pixels) covered += v > 0.5f;
      EXPECT_GT(covered / mask.pixels.size(), 0.1) << name << " " << method;
    }
  }
}

TEST_F(WebServer, RendersAnUploadedMeshById) {
  const std::string mesh = objMesh(example("torus_creased"));
  HttpResponse uploaded = post(port(), "/v1/meshes", R"({"mesh":)" + mesh + "}");
  ASSERT_EQ(uploaded.status, 200) << uploaded.body;
  rapidjson::Document info = parse(uploaded.body);
  EXPECT_EQ(info["vertices"].GetInt(), 96);
  EXPECT_EQ(info["faces"].GetInt(), 96);
  EXPECT_STREQ(info["scheme"].GetString(), "catmull-clark");
  const std::string id = info["id"].GetString();
  EXPECT_EQ(id.size(), 32u);
  EXPECT_EQ(upload(mesh), id) << "the same mesh gets the same id";
  EXPECT_NE(upload(objMesh(example("torus_creased"), "bilinear")), id) << "scheme is part of it";

  const std::string rest =
      R"(,"method":"uniform","params":{"level":2},"camera":{"width":96,"height":96}})";
  HttpResponse byId = post(port(), "/v1/render", R"({"mesh":{"id":")" + id + "\"}" + rest);
  HttpResponse inline_ = post(port(), "/v1/render", R"({"mesh":)" + mesh + rest);
  ASSERT_EQ(byId.status, 200) << byId.body.substr(0, 300);
  ASSERT_EQ(inline_.status, 200);
  rapidjson::Document a = parse(byId.body), b = parse(inline_.body);
  EXPECT_EQ(a["stats"]["triangles"].GetInt64(), 96 * 2 * 16);
  EXPECT_STREQ(a["images"]["color"]["data"].GetString(), b["images"]["color"]["data"].GetString());

  // The contour endpoint takes the id too.
  HttpResponse contours =
      post(port(), "/v1/silhouette", R"({"mesh":{"id":")" + id + R"("},"format":"svg"})");
  EXPECT_EQ(contours.status, 200) << contours.body.substr(0, 300);
  EXPECT_EQ(contours.header("Content-Type"), "image/svg+xml");
}

TEST_F(WebServer, RefusesUnknownIdsAndBrokenUploadsInWords) {
  HttpResponse unknown =
      post(port(), "/v1/render", R"({"mesh":{"id":"00000000000000000000000000000000"}})");
  EXPECT_EQ(unknown.status, 404);
  rapidjson::Document doc = parse(unknown.body);
  EXPECT_STREQ(doc["error"]["code"].GetString(), "unknown_mesh");
  EXPECT_STREQ(doc["error"]["detail"]["field"].GetString(), "mesh.id");

  const std::string id = upload(objMesh(example("cube")));
  HttpResponse withScheme =
      post(port(), "/v1/render", R"({"mesh":{"id":")" + id + R"(","scheme":"loop"}})");
  EXPECT_EQ(withScheme.status, 400);
  EXPECT_NE(withScheme.body.find("mesh.scheme cannot go with it"), std::string::npos)
      << withScheme.body;

  HttpResponse broken =
      post(port(), "/v1/meshes",
           R"({"mesh":)" + objMesh("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 7\n") + "}");
  EXPECT_EQ(broken.status, 422);
  EXPECT_NE(broken.body.find("line 5: face 1 uses vertex 7"), std::string::npos) << broken.body;
  HttpResponse loopQuads =
      post(port(), "/v1/meshes", R"({"mesh":)" + objMesh(example("cube"), "loop") + "}");
  EXPECT_EQ(loopQuads.status, 422) << "validated at upload, not at the first render";
  EXPECT_EQ(post(port(), "/v1/meshes", R"({"mesh":{"id":"x"}})").status, 400);
  EXPECT_EQ(post(port(), "/v1/meshes", "{}").status, 400);
}

// The server keeps meshCacheBytes (40000 here): uploading more evicts the least recently used,
// whose id then answers 404 unknown_mesh, and a mesh over the whole bound is a 413.
TEST_F(WebServer, EvictsTheLeastRecentlyUsedMeshes) {
  const std::string pawn = upload(objMesh(example("pawn")));  // about 5 kB
  const std::string cube = upload(objMesh(example("cube")));
  std::string grid;
  for (int i = 0; i < 30; ++i) {
    // Different meshes of about 2 kB each: one more point each time.
    std::string obj = example("grid");
    obj += "v " + std::to_string(i) + " 0 0\n";
    grid = upload(objMesh(obj));
    // Keep the cube recently used.
    EXPECT_EQ(post(port(), "/v1/render",
                   R"({"mesh":{"id":")" + cube + R"("},"outputs":[],"method":"coarse"})")
                  .status,
              200);
  }
  EXPECT_EQ(post(port(), "/v1/render", R"({"mesh":{"id":")" + pawn + R"("},"outputs":[]})").status,
            404);
  EXPECT_EQ(post(port(), "/v1/render", R"({"mesh":{"id":")" + grid + R"("},"outputs":[]})").status,
            200);

  std::string big = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  for (int i = 0; i < 3000; ++i) big += "v " + std::to_string(i) + " 1 1\n";
  big += "f 1 2 3\n";
  HttpResponse tooBig = post(port(), "/v1/meshes", R"({"mesh":)" + objMesh(big) + "}");
  EXPECT_EQ(tooBig.status, 413);
  EXPECT_NE(tooBig.body.find("meshCacheBytes"), std::string::npos) << tooBig.body;
}

TEST_F(WebServer, PlacesTheEyeByOrbit) {
  const std::string mesh = objMesh(example("cube"));
  auto eyeOf = [&](const std::string& orbit) {
    HttpResponse r =
        post(port(), "/v1/render",
             R"({"mesh":)" + mesh + R"(,"outputs":[],"method":"coarse","camera":{"orbit":)" +
                 orbit + "}}");
    EXPECT_EQ(r.status, 200) << r.body.substr(0, 300);
    rapidjson::Document doc = parse(r.body);
    const auto& e = doc["camera"]["eye"];
    return std::array<double, 3>{e[0].GetDouble(), e[1].GetDouble(), e[2].GetDouble()};
  };
  // The cube's bounding sphere has radius sqrt(3); distance is in radii.
  const double r = std::sqrt(3.0);
  auto side = eyeOf(R"({"azimuthDeg":90,"elevationDeg":0,"distance":4})");
  EXPECT_NEAR(side[0], 4 * r, 1e-9);
  EXPECT_NEAR(side[1], 0, 1e-9);
  EXPECT_NEAR(side[2], 0, 1e-9);
  auto above = eyeOf(R"({"azimuthDeg":0,"elevationDeg":90,"distance":2})");
  EXPECT_NEAR(above[1], 2 * r, 1e-9);
  // Without a distance: the default framing, the same eye as no camera at all from +Z.
  auto framed = eyeOf(R"({})");
  HttpResponse plain =
      post(port(), "/v1/render", R"({"mesh":)" + mesh + R"(,"outputs":[],"method":"coarse"})");
  rapidjson::Document doc = parse(plain.body);
  EXPECT_NEAR(framed[2], doc["camera"]["eye"][2].GetDouble(), 1e-9);

  auto refuse = [&](const std::string& camera, const char* field) {
    HttpResponse r =
        post(port(), "/v1/render", R"({"mesh":)" + mesh + R"(,"camera":)" + camera + "}");
    EXPECT_EQ(r.status, 400) << camera;
    EXPECT_NE(r.body.find(std::string("\"field\":\"") + field + "\""), std::string::npos) << r.body;
  };
  refuse(R"({"orbit":{"azimuthDeg":0},"eye":[0,0,5]})", "camera.orbit");
  refuse(R"({"orbit":{"elevationDeg":95}})", "camera.orbit.elevationDeg");
  refuse(R"({"orbit":{"distance":0}})", "camera.orbit.distance");
  refuse(R"({"orbit":{"azimuthDeg":"east"}})", "camera.orbit.azimuthDeg");
}

TEST_F(WebServer, DrawsTheDifferenceFromTheReference) {
  const std::string mesh = objMesh(example("pawn"));
  auto diffOf = [&](int level) {
    HttpResponse r = post(
        port(), "/v1/render",
        R"({"mesh":)" + mesh + R"(,"method":"uniform","params":{"level":)" + std::to_string(level) +
            R"(},"outputs":["color","diff"],"reference":true,"camera":{"width":128,"height":128}})");
    EXPECT_EQ(r.status, 200) << r.body.substr(0, 300);
    return parse(r.body);
  };
  rapidjson::Document coarse = diffOf(0), fine = diffOf(3);
  for (const rapidjson::Document* doc : {&coarse, &fine}) {
    ASSERT_TRUE((*doc)["images"].HasMember("diff"));
    EXPECT_FALSE((*doc)["reference"]["images"].HasMember("diff"));
    EXPECT_GT((*doc)["metrics"]["image"]["diffScale"].GetDouble(), 0);
  }
  render::Image heat =
      render::image::decode(decodeBase64(coarse["images"]["diff"]["data"].GetString()));
  EXPECT_EQ(heat.width, 128);
  EXPECT_EQ(heat.channels, 4);
  // Opaque where the surface is (either rendering), transparent around it.
  EXPECT_EQ(heat.at(0, 0, 3), 0.0f);
  EXPECT_EQ(heat.at(64, 64, 3), 1.0f);
  // The cage (level 0) is much further from the limit than level 3: the larger difference.
  EXPECT_GT(coarse["metrics"]["image"]["diffScale"].GetDouble(),
            fine["metrics"]["image"]["diffScale"].GetDouble() * 0.99);
  EXPECT_GT(coarse["metrics"]["image"]["rmse"].GetDouble(),
            2 * fine["metrics"]["image"]["rmse"].GetDouble());

  HttpResponse noReference =
      post(port(), "/v1/render", R"({"mesh":)" + mesh + R"(,"outputs":["diff"]})");
  EXPECT_EQ(noReference.status, 400);
  EXPECT_NE(noReference.body.find("needs \\\"reference\\\": true"), std::string::npos)
      << noReference.body;
}

uint32_t u32(const std::string& bytes, size_t at) {
  uint32_t v;
  std::memcpy(&v, bytes.data() + at, 4);
  return v;  // little-endian, like the machines this runs on
}

// POST /v1/tessellate: the approximation as GLB (default), PLY or OBJ, the same triangles a
// render of the same request counts, with a normal per vertex.
TEST_F(WebServer, AnswersTheApproximationsMesh) {
  const std::string request = R"({"mesh":)" + objMesh(example("torus_creased")) +
                              R"(,"method":"uniform","params":{"level":2}})";
  HttpResponse rendered = post(port(), "/v1/render", request);
  const int64_t triangles = parse(rendered.body)["stats"]["triangles"].GetInt64();
  ASSERT_EQ(triangles, 96 * 2 * 16);

  HttpResponse glb = post(port(), "/v1/tessellate", request);
  ASSERT_EQ(glb.status, 200) << glb.body.substr(0, 300);
  EXPECT_EQ(glb.header("Content-Type"), "model/gltf-binary");
  EXPECT_EQ(glb.header("X-Limn-Triangles"), std::to_string(triangles));
  ASSERT_GT(glb.body.size(), 28u);
  EXPECT_EQ(glb.body.substr(0, 4), "glTF");
  EXPECT_EQ(u32(glb.body, 4), 2u);
  EXPECT_EQ(u32(glb.body, 8), glb.body.size());
  const uint32_t jsonLength = u32(glb.body, 12);
  EXPECT_EQ(jsonLength % 4, 0u);
  EXPECT_EQ(glb.body.substr(16, 4), "JSON");
  rapidjson::Document gltf = parse(glb.body.substr(20, jsonLength));
  ASSERT_FALSE(gltf.HasParseError());
  EXPECT_STREQ(gltf["asset"]["version"].GetString(), "2.0");
  EXPECT_EQ(gltf["asset"]["extras"]["stats"]["triangles"].GetInt64(), triangles);
  const auto& primitive = gltf["meshes"][0]["primitives"][0];
  const auto& accessors = gltf["accessors"];
  const int vertices = accessors[primitive["attributes"]["POSITION"].GetInt()]["count"].GetInt();
  EXPECT_EQ(accessors[primitive["attributes"]["NORMAL"].GetInt()]["count"].GetInt(), vertices);
  EXPECT_EQ(accessors[primitive["indices"].GetInt()]["count"].GetInt64(), 3 * triangles);
  const size_t binAt = 20 + jsonLength;
  EXPECT_EQ(glb.body.substr(binAt + 4, 4), std::string("BIN\0", 4));
  EXPECT_EQ(u32(glb.body, binAt), gltf["buffers"][0]["byteLength"].GetUint());
  EXPECT_EQ(u32(glb.body, binAt), vertices * 24u + triangles * 12u);
  // Every index names a vertex; every normal is unit length.
  const size_t indicesAt = binAt + 8 + vertices * 24u;
  for (int64_t i = 0; i < 3 * triangles; ++i) {
    ASSERT_LT(u32(glb.body, indicesAt + 4 * i), static_cast<uint32_t>(vertices));
  }
  for (int i = 0; i < vertices; ++i) {
    float n[3];
    std::memcpy(n, glb.body.data() + binAt + 8 + vertices * 12u + 12u * i, 12);
    ASSERT_NEAR(std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]), 1.0, 1e-4) << i;
  }

  HttpResponse ply = post(port(), "/v1/tessellate", request, {{"Accept", "application/x-ply"}});
  ASSERT_EQ(ply.status, 200);
  EXPECT_EQ(ply.header("Content-Type"), "application/x-ply");
  EXPECT_EQ(ply.body.rfind("ply\nformat binary_little_endian 1.0\n", 0), 0u);
  EXPECT_NE(ply.body.find("element vertex " + std::to_string(vertices) + "\n"), std::string::npos);
  EXPECT_NE(ply.body.find("property float nx\n"), std::string::npos);
  EXPECT_NE(ply.body.find("element face " + std::to_string(triangles) + "\n"), std::string::npos);
  const size_t header = ply.body.find("end_header\n") + 11;
  EXPECT_EQ(ply.body.size() - header, vertices * 24u + triangles * 13u);

  // The OBJ is one limn reads back: the same counts as a bilinear mesh (the cube refined once:
  // small enough for this server's mesh cache).
  HttpResponse obj = post(
      port(), "/v1/tessellate",
      R"({"mesh":)" + objMesh(example("cube")) + R"(,"method":"uniform","params":{"level":1}})",
      {{"Accept", "text/plain"}});
  ASSERT_EQ(obj.status, 200);
  EXPECT_NE(obj.body.find("\nvn "), std::string::npos);
  HttpResponse again =
      post(port(), "/v1/meshes", R"({"mesh":)" + objMesh(obj.body, "bilinear") + "}");
  ASSERT_EQ(again.status, 200) << again.body;
  EXPECT_EQ(parse(again.body)["vertices"].GetInt(), 26);
  EXPECT_EQ(parse(again.body)["faces"].GetInt(), 48);
  EXPECT_EQ(obj.header("X-Limn-Triangles"), "48");

  // Adaptive depends on the camera: the orbit and size are honoured.
  const std::string adaptive = R"({"mesh":)" + objMesh(example("pawn")) +
                               R"(,"method":"adaptive","params":{"dicingRate":4},"camera":)";
  HttpResponse small = post(port(), "/v1/tessellate", adaptive + R"({"width":128,"height":128}})");
  HttpResponse large =
      post(port(), "/v1/tessellate", adaptive + R"({"width":1024,"height":1024}})");
  EXPECT_LT(std::stoll(small.header("X-Limn-Triangles")),
            std::stoll(large.header("X-Limn-Triangles")));

  HttpResponse png = post(port(), "/v1/tessellate", request, {{"Accept", "image/png"}});
  EXPECT_EQ(png.status, 406);
  EXPECT_STREQ(parse(png.body)["error"]["code"].GetString(), "not_acceptable");
  HttpResponse limit = post(port(), "/v1/tessellate",
                            R"({"mesh":)" + objMesh(example("cube")) + R"(,"method":"limit"})");
  EXPECT_EQ(limit.status, 400);
  EXPECT_STREQ(parse(limit.body)["error"]["detail"]["field"].GetString(), "method");
  HttpResponse broken =
      post(port(), "/v1/tessellate", R"({"mesh":)" + objMesh("v 0 0 0\nf 1 2 3\n") + "}");
  EXPECT_EQ(broken.status, 422);
}

// A page that moves the camera aborts the request it no longer needs; the server sees the
// connection close and stops that work: a queued job leaves the queue, a running one is
// cancelled and its worker freed, before the job would have finished (about 5 s here, far more
// under the sanitizers).
TEST(AbandonedRequests, StopTheWorkOfAClientThatWentAway) {
  ServerProcess server = ServerProcess::withConfig(R"({"workers": 1})");
  const std::string obj = get(server.port(), "/examples/pawn").body;
  const std::string slow = R"({"mesh":)" + objMesh(obj) +
                           R"(,"method":"uniform","params":{"level":6,"metricSupersample":8},)"
                           R"("camera":{"width":1024,"height":1024},"reference":true})";
  auto raw = [&](const std::string& body) {
    return "POST /v1/render HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/json\r\n"
           "Content-Length: " +
           std::to_string(body.size()) + "\r\n\r\n" + body;
  };
  auto health = [&] { return parse(get(server.port(), "/healthz").body); };
  auto abandoned = [&] {
    const std::string metrics = get(server.port(), "/metrics").body;
    const std::string key = "limn_render_jobs_refused_total{reason=\"abandoned\"} ";
    const size_t at = metrics.find(key);
    return at == std::string::npos ? -1 : std::stoi(metrics.substr(at + key.size()));
  };
  // Generous: on a loaded 2-core machine the engine's next cancellation check can be seconds
  // away; the abandoned counter, not the time, is what shows the job was dropped.
  auto waitFor = [&](const std::function<bool()>& done) {
    for (int i = 0; i < 1200 && !done(); ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    return done();
  };

  auto running = std::make_unique<HttpClient>(server.port());
  running->send(raw(slow));
  ASSERT_TRUE(waitFor([&] { return health()["busyWorkers"].GetInt() == 1; }));
  {
    HttpClient queued(server.port());
    queued.send(raw(slow));
    ASSERT_TRUE(waitFor([&] { return health()["queueDepth"].GetInt() == 1; }));
  }  // closes the connection
  EXPECT_TRUE(waitFor([&] { return health()["queueDepth"].GetInt() == 0; }));
  EXPECT_EQ(abandoned(), 1);
  EXPECT_EQ(health()["busyWorkers"].GetInt(), 1) << "the first job still runs";

  const auto closed = std::chrono::steady_clock::now();
  running.reset();
  EXPECT_TRUE(waitFor([&] { return health()["busyWorkers"].GetInt() == 0; }));
  const double freedAfterS =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - closed).count();
  EXPECT_EQ(abandoned(), 2);
  std::printf("worker freed %.2f s after its client closed the connection\n", freedAfterS);
  // The worker is free for the next request.
  HttpResponse next = post(server.port(), "/v1/render",
                           R"({"mesh":)" + objMesh(obj) + R"(,"camera":{"width":64,"height":64}})");
  EXPECT_EQ(next.status, 200);
  EXPECT_EQ(server.terminate(SIGTERM), 0);
}

}  // namespace
}  // namespace limn::testing
