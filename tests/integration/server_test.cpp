// The real `limn serve` process on 127.0.0.1: service endpoints, a render, every class of bad
// request, limits, concurrency, back-pressure, timeouts, keep-alive and a clean SIGTERM.
#include <gtest/gtest.h>
#include <rapidjson/document.h>
#include <sys/stat.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "tests/integration/http_client.h"
#include "tests/integration/json_answer.h"
#include "tests/integration/openapi_check.h"
#include "tests/integration/server_process.h"

namespace limn::testing {
namespace {

using namespace std::chrono_literals;

// A unit cube as OBJ text with JSON-escaped newlines.
const char* kCubeObj =
    "v -1 -1 1\\nv 1 -1 1\\nv -1 1 1\\nv 1 1 1\\nv -1 1 -1\\nv 1 1 -1\\nv -1 -1 -1\\nv 1 -1 -1\\n"
    "f 1 2 4 3\\nf 3 4 6 5\\nf 5 6 8 7\\nf 7 8 2 1\\nf 2 8 6 4\\nf 7 1 3 5\\n";

std::string renderBody(const std::string& method, int size, const std::string& extra = "") {
  return std::string(R"({"mesh": {"format": "obj", "data": ")") + kCubeObj +
         R"("}, "camera": {"width": )" + std::to_string(size) +
         ", \"height\": " + std::to_string(size) + R"(}, "method": ")" + method + "\"" + extra +
         "}";
}

std::string smallRender() { return renderBody("coarse", 64, R"(, "outputs": ["color"])"); }

// About a second on llvmpipe (200k triangles at 1024^2, three passes): long enough that
// requests sent together overlap, short enough to keep the tests quick.
std::string slowRender() {
  return renderBody("adaptive", 1024,
                    R"(, "params": {"dicingRate": 0.25}, "outputs": ["color", "depth", "normal"])");
}

// The error code of a JSON error answer, or a description of what the body was instead.
std::string errorCode(const HttpResponse& response) {
  auto doc = parseJson(response.body);
  if (doc.HasParseError() || !doc.IsObject() || !doc.HasMember("error") ||
      !doc["error"].IsObject() || !doc["error"].HasMember("code")) {
    return "<not a JSON error: " + response.body.substr(0, 200) + ">";
  }
  return doc["error"]["code"].GetString();
}

// A server shared by the tests that do not change its configuration.
class ServerTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    server_ = new ServerProcess(ServerProcess::withConfig(R"({"workers": 2, "queueDepth": 64})"));
  }
  static void TearDownTestSuite() {
    EXPECT_EQ(server_->terminate(SIGTERM), 0) << "a clean shutdown exits with status 0";
    delete server_;
    server_ = nullptr;
  }
  static int port() { return server_->port(); }

  static ServerProcess* server_;
};
ServerProcess* ServerTest::server_ = nullptr;

TEST_F(ServerTest, HealthzDescribesTheService) {
  HttpResponse r = get(port(), "/healthz");
  ASSERT_EQ(r.status, 200);
  EXPECT_EQ(r.header("Content-Type"), "application/json");
  auto doc = parseJson(r.body);
  ASSERT_FALSE(doc.HasParseError()) << r.body;
  EXPECT_STREQ(doc["status"].GetString(), "ok") << r.body;
  EXPECT_EQ(doc["workers"].GetInt(), 2);
  EXPECT_EQ(doc["queueCapacity"].GetInt(), 64);
  EXPECT_EQ(doc["queueDepth"].GetInt(), 0);
  EXPECT_FALSE(std::string(doc["renderer"].GetString()).empty());
  EXPECT_FALSE(std::string(doc["eglPlatform"].GetString()).empty());
  EXPECT_FALSE(std::string(doc["version"].GetString()).empty());
}

TEST_F(ServerTest, ReadyzSaysReady) {
  HttpResponse r = get(port(), "/readyz");
  EXPECT_EQ(r.status, 200);
  auto doc = parseJson(r.body);
  ASSERT_FALSE(doc.HasParseError()) << r.body;
  EXPECT_TRUE(doc["ready"].GetBool());
}

TEST_F(ServerTest, MetricsCountWhatWasAnswered) {
  ASSERT_EQ(post(port(), "/v1/render", smallRender()).status, 200);
  ASSERT_EQ(get(port(), "/no/such/thing").status, 404);
  HttpResponse r = get(port(), "/metrics");
  ASSERT_EQ(r.status, 200);
  EXPECT_EQ(r.header("Content-Type").rfind("text/plain", 0), 0u);
  EXPECT_NE(r.body.find("limn_requests_total{path=\"/v1/render\",status=\"200\"} "),
            std::string::npos)
      << r.body;
  EXPECT_NE(r.body.find("limn_requests_total{path=\"other\",status=\"404\"} "), std::string::npos);
  EXPECT_NE(r.body.find("limn_request_duration_seconds_count{path=\"/v1/render\",status=\"200\"} "),
            std::string::npos);
  EXPECT_NE(r.body.find("\nlimn_queue_depth 0\n"), std::string::npos);
  EXPECT_NE(r.body.find("\nlimn_workers_busy "), std::string::npos);
  EXPECT_NE(r.body.find("\nlimn_render_seconds_count "), std::string::npos);
}

// What a Prometheus server scraping limn would read: the text goes through Prometheus' own
// parser (Debian's python3-prometheus-client), and the histograms are there with samples.
TEST_F(ServerTest, MetricsParseAsPrometheusTextWithHistograms) {
  ASSERT_EQ(post(port(), "/v1/render", smallRender()).status, 200);
  HttpResponse r = get(port(), "/metrics");
  ASSERT_EQ(r.status, 200);
  const std::string path = writeTempFile(r.body, ".prom");
  CommandResult parsed = runCommand(
      "/usr/bin/python3 '" LIMN_SOURCE_DIR "/tests/integration/parse_metrics.py' '" + path + "'");
  std::remove(path.c_str());
  ASSERT_EQ(parsed.status, 0) << parsed.output << "\n--- the text ---\n" << r.body;
  // name -> (type, samples)
  std::map<std::string, std::pair<std::string, int>> families;
  std::istringstream lines(parsed.output);
  for (std::string name, type; lines >> name >> type;) {
    int samples = 0;
    lines >> samples;
    families[name] = {type, samples};
  }
  for (const char* histogram :
       {"limn_request_duration_seconds", "limn_queue_wait_seconds", "limn_render_seconds",
        "limn_render_stage_seconds", "limn_mesh_faces"}) {
    ASSERT_TRUE(families.count(histogram)) << histogram << " missing:\n" << parsed.output;
    EXPECT_EQ(families[histogram].first, "histogram") << histogram;
    EXPECT_GT(families[histogram].second, 0) << histogram << " has no samples";
  }
  EXPECT_EQ(families["limn_queue_depth"].first, "gauge");
  // Prometheus' parser drops _total from counter names.
  EXPECT_EQ(families["limn_requests"].first, "counter") << parsed.output;
}

TEST_F(ServerTest, OpenApiDocumentDescribesRender) {
  HttpResponse r = get(port(), "/openapi.json");
  ASSERT_EQ(r.status, 200);
  auto doc = parseJson(r.body);
  ASSERT_FALSE(doc.HasParseError());
  ASSERT_TRUE(doc.HasMember("paths"));
  EXPECT_TRUE(doc["paths"].HasMember("/v1/render"));
}

// The document against the server's real answers: every status and media type the server
// sent is declared for its operation, and every JSON body validates against the declared
// schema with no undocumented field (tests/integration/check_openapi.py, python3-jsonschema).
TEST_F(ServerTest, RealAnswersMatchTheOpenApiDocument) {
  const std::string silhouetteStats =
      renderBody("silhouette", 64, R"(, "outputs": ["color", "contours"], "reference": true)");
  const std::vector<ApiExchange> exchanges = {
      {"POST", "/v1/render", "",
       renderBody("adaptive", 64,
                  R"(, "outputs": ["color", "mask", "depth", "normal", "wireframe", "cage"],
                     "reference": true, "params": {"referenceCrossCheck": true})")},
      {"POST", "/v1/render", "", silhouetteStats},
      {"POST", "/v1/render", "",
       renderBody("uniform", 64, R"(, "params": {"level": 2}, "imageFormat": "exr")")},
      {"POST", "/v1/render", "", renderBody("limit", 64, R"(, "outputs": ["color"], "extra": 1)")},
      {"POST", "/v1/render", "",
       renderBody(
           "adaptive", 64,
           R"(, "outputs": ["mask", "turntable"], "reference": true, "turntable": {"frames": 3})")},
      {"POST",
       "/v1/meshes",
       "",
       "OFF\n4 4 0\n1 1 1\n-1 -1 1\n-1 1 -1\n1 -1 -1\n3 0 1 3\n3 0 2 1\n3 0 3 2\n3 1 2 3\n",
       {{"Content-Type", "model/x-off"}}},
      {"POST", "/v1/meshes", "", "solid x", {{"Content-Type", "image/png"}}},
      {"POST", "/v1/render", "", "{\"mesh\": "},
      {"POST", "/v1/render", "", renderBody("uniform", 64, R"(, "params": {"level": 99})")},
      {"POST", "/v1/render", "", R"({"mesh": {"format": "obj", "data": "v 0 0 0\nf 1 2 3\n"}})"},
      {"GET", "/v1/render", "", ""},
      {"POST", "/v1/silhouette", "", renderBody("silhouette", 64, "")},
      {"POST",
       "/v1/silhouette",
       "",
       renderBody("silhouette", 64, ""),
       {{"Accept", "image/svg+xml"}}},
      {"POST", "/v1/silhouette", "", R"({"mesh": 5})"},
      {"GET", "/healthz", "", ""},
      {"GET", "/readyz", "", ""},
      {"GET", "/metrics", "", ""},
      {"GET", "/openapi.json", "", ""},
      {"POST", "/healthz", "", ""},
  };
  OpenApiCheck check = checkAgainstOpenApi(port(), exchanges);
  EXPECT_EQ(check.status, 0) << check.output;
  EXPECT_EQ(check.statuses, (std::set<int>{200, 400, 405, 413, 415, 422}))
      << "the exchanges cover these";
}

TEST_F(ServerTest, RenderOfACubeAnswersAPng) {
  HttpResponse r = post(port(), "/v1/render", smallRender());
  ASSERT_EQ(r.status, 200) << r.body.substr(0, 400);
  // Every answer names its line in the request log; ids only grow.
  uint64_t id = std::stoull(r.header("X-Request-Id"));
  EXPECT_GT(std::stoull(get(port(), "/healthz").header("X-Request-Id")), id);
  auto doc = parseJson(r.body);
  ASSERT_FALSE(doc.HasParseError());
  const auto& color = doc["images"]["color"];
  EXPECT_STREQ(color["mime"].GetString(), "image/png");
  EXPECT_EQ(color["width"].GetInt(), 64);
  EXPECT_EQ(color["height"].GetInt(), 64);
  std::vector<unsigned char> png = decodeBase64(color["data"].GetString());
  const unsigned char signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  ASSERT_GT(png.size(), 24u);
  EXPECT_TRUE(std::equal(signature, signature + 8, png.begin()));
  // IHDR: width and height, big-endian, at bytes 16..23.
  auto be32 = [&](size_t at) {
    return (png[at] << 24) | (png[at + 1] << 16) | (png[at + 2] << 8) | png[at + 3];
  };
  EXPECT_EQ(be32(16), 64);
  EXPECT_EQ(be32(20), 64);
  EXPECT_EQ(doc["stats"]["controlFaces"].GetInt(), 6);
}

// A second request for the same mesh and view (another method) takes the reference's
// tessellation and BVH from the cache, says so, measures the same continuous outline distance
// for the same approximation, and /metrics counts the hit.
TEST_F(ServerTest, SecondReferenceForTheSameViewComesFromTheCache) {
  const std::string camera = R"(, "camera": {"width": 160, "height": 160, "eye": [2.1, 1.7, 3.3]})";
  auto body = [&](const char* method) {
    return std::string(R"({"mesh": {"format": "obj", "data": ")") + kCubeObj + R"("})" + camera +
           R"(, "method": ")" + method + R"(", "reference": true, "outputs": ["color"]})";
  };
  HttpResponse first = post(port(), "/v1/render", body("coarse"));
  HttpResponse second = post(port(), "/v1/render", body("uniform"));
  HttpResponse third = post(port(), "/v1/render", body("coarse"));
  ASSERT_EQ(first.status, 200) << first.body.substr(0, 300);
  ASSERT_EQ(second.status, 200) << second.body.substr(0, 300);
  ASSERT_EQ(third.status, 200) << third.body.substr(0, 300);
  auto a = parseJson(first.body), b = parseJson(second.body), c = parseJson(third.body);
  EXPECT_FALSE(a["timings"]["referenceStages"]["sceneCached"].GetBool());
  EXPECT_TRUE(b["timings"]["referenceStages"]["sceneCached"].GetBool());
  EXPECT_TRUE(c["timings"]["referenceStages"]["sceneCached"].GetBool());
  // The cage of a cube is far from its limit surface; level 3 is close: the continuous metric
  // ranks them, and is the same number for the same approximation, cached or not.
  double coarsePx = a["metrics"]["silhouette"]["outlineHausdorffPx"].GetDouble();
  double uniformPx = b["metrics"]["silhouette"]["outlineHausdorffPx"].GetDouble();
  EXPECT_GT(coarsePx, 5.0);
  EXPECT_LT(uniformPx, coarsePx / 4);
  EXPECT_DOUBLE_EQ(c["metrics"]["silhouette"]["outlineHausdorffPx"].GetDouble(), coarsePx);
  EXPECT_FALSE(a["stats"].HasMember("referenceCrossCheckPx"));  // only when asked for

  HttpResponse metrics = get(port(), "/metrics");
  EXPECT_NE(metrics.body.find("limn_reference_cache_lookups_total{result=\"hit\"}"),
            std::string::npos);
  EXPECT_EQ(metrics.body.find("limn_reference_cache_lookups_total{result=\"hit\"} 0\n"),
            std::string::npos);
}

// A flat fan of n Loop triangles around one vertex (valence n), as a JSON-ready OBJ string.
std::string fanObj(int n) {
  std::string obj = "v 0 0 0\\n";
  for (int k = 0; k < n; ++k) {
    double a = 2 * 3.14159265358979 * k / n;
    obj += "v " + std::to_string(std::cos(a)) + " " + std::to_string(std::sin(a)) + " 0\\n";
  }
  for (int k = 0; k < n; ++k) {
    obj += "f 1 " + std::to_string(k + 2) + " " + std::to_string((k + 1) % n + 2) + "\\n";
  }
  return obj;
}

// High valence: over limits.maxValence a quick 422 names the vertex and the limit (building the
// limit surface around it would take minutes); under it, every method and the reference answer.
TEST_F(ServerTest, HighValenceIsRefusedByNameOrRendered) {
  auto body = [](int n, const char* method) {
    return R"({"mesh": {"format": "obj", "scheme": "loop", "data": ")" + fanObj(n) +
           R"("}, "camera": {"width": 128, "height": 128, "eye": [0.3, 0.4, 3]}, "method": ")" +
           method + R"(", "reference": true})";
  };
  auto start = std::chrono::steady_clock::now();
  HttpResponse refused = post(port(), "/v1/render", body(5000, "coarse"));
  EXPECT_LT(std::chrono::steady_clock::now() - start, 5s);
  EXPECT_EQ(refused.status, 422) << refused.body.substr(0, 300);
  EXPECT_EQ(errorCode(refused), "invalid_mesh");
  EXPECT_NE(refused.body.find("vertex 0"), std::string::npos) << refused.body;
  EXPECT_NE(refused.body.find("maxValence"), std::string::npos) << refused.body;
  for (const char* method : {"coarse", "adaptive", "silhouette"}) {
    HttpResponse ok = post(port(), "/v1/render", body(200, method));
    EXPECT_EQ(ok.status, 200) << method << ": " << ok.body.substr(0, 300);
  }
}

// The silhouette method through the server: exact outline on the cube, its counts, the
// contour overlay as an extra image, and normal-map shading.
TEST_F(ServerTest, SilhouetteMethodAnswersWithItsStatsAndOverlay) {
  HttpResponse r = post(port(), "/v1/render",
                        renderBody("silhouette", 256,
                                   R"(, "shading": "normal-map", "reference": true,)"
                                   R"( "outputs": ["color", "contours", "normal"])"));
  ASSERT_EQ(r.status, 200) << r.body.substr(0, 400);
  auto doc = parseJson(r.body);
  const auto& images = doc["images"];
  ASSERT_TRUE(images.HasMember("contours"));
  ASSERT_TRUE(images.HasMember("color"));
  // The overlay draws lines over the colour: the two images differ.
  EXPECT_NE(std::string(images["contours"]["data"].GetString()),
            std::string(images["color"]["data"].GetString()));
  const auto& silhouette = doc["stats"]["silhouette"];
  EXPECT_TRUE(silhouette["presubdivided"].GetBool());  // 6 faces: "auto" refines
  EXPECT_GT(silhouette["contourFaces"].GetUint64(), 0u);
  EXPECT_GT(silhouette["contourPoints"].GetUint64(), 0u);
  EXPECT_EQ(silhouette["trianglesDrawn"].GetUint64(), doc["stats"]["triangles"].GetUint64());
  EXPECT_LE(doc["metrics"]["silhouette"]["hausdorffPx"].GetDouble(), 0.5);
  // Normal-map shading reads limit normals per pixel: closer to the reference's normals than
  // per-vertex interpolation, and far closer than flat facets. (Not equal: a pixel of the
  // coarse mesh sees a chord, whose point lies off the surface point the reference sees.)
  auto meanDeg = [&](const std::string& shading) {
    HttpResponse answer = post(port(), "/v1/render",
                               renderBody("silhouette", 256,
                                          R"(, "shading": ")" + shading +
                                              R"(", "reference": true, "outputs": ["normal"])"));
    EXPECT_EQ(answer.status, 200);
    return parseJson(answer.body)["metrics"]["normal"]["meanDeg"].GetDouble();
  };
  double mapped = doc["metrics"]["normal"]["meanDeg"].GetDouble();
  EXPECT_LT(mapped, meanDeg("smooth"));
  EXPECT_LT(2 * mapped, meanDeg("flat"));
}

struct BadRequest {
  const char* name;
  std::string method, path, body;
  int status;
  const char* code;
};

TEST_F(ServerTest, EveryBadRequestGetsItsJsonErrorAndTheServerCarriesOn) {
  const std::vector<BadRequest> cases = {
      {"invalid JSON", "POST", "/v1/render", "{\"mesh\": ", 400, "invalid_json"},
      {"unknown method", "POST", "/v1/render", renderBody("bogus", 64), 400, "invalid_request"},
      {"face index out of range", "POST", "/v1/render",
       R"({"mesh": {"format": "obj", "data": "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n"}})", 422,
       "invalid_mesh"},
      {"contours from another method", "POST", "/v1/render",
       renderBody("adaptive", 64, R"(, "outputs": ["contours"])"), 400, "invalid_request"},
      {"bad presubdivide", "POST", "/v1/render",
       renderBody("silhouette", 64, R"(, "params": {"presubdivide": 2})"), 400, "invalid_request"},
      {"bad contour", "POST", "/v1/render",
       renderBody("silhouette", 64, R"(, "params": {"contour": "spline"})"), 400,
       "invalid_request"},
      {"too many search steps", "POST", "/v1/render",
       renderBody("silhouette", 64, R"(, "params": {"searchSteps": 1000})"), 413, "too_large"},
      {"normal-map on uniform", "POST", "/v1/render",
       renderBody("uniform", 64, R"(, "shading": "normal-map")"), 400, "invalid_request"},
      {"unknown path", "GET", "/v2/everything", "", 404, "not_found"},
      {"wrong verb", "GET", "/v1/render", "", 405, "method_not_allowed"},
      {"wrong verb on healthz", "POST", "/healthz", "{}", 405, "method_not_allowed"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    HttpResponse r = HttpClient(port()).request(c.method, c.path, c.body);
    EXPECT_EQ(r.status, c.status) << r.body.substr(0, 300);
    EXPECT_EQ(r.header("Content-Type"), "application/json");
    EXPECT_EQ(errorCode(r), c.code);
    if (c.status == 405) {
      EXPECT_FALSE(r.header("Allow").empty());
    }
    EXPECT_EQ(post(port(), "/v1/render", smallRender()).status, 200);
  }
}

TEST_F(ServerTest, MalformedHttpGets400Json) {
  for (const char* garbage : {"HELLO\r\n\r\n", "GET /healthz HTTP/9.9\r\n\r\n",
                              "POST /v1/render HTTP/1.1\r\nContent-Length: abc\r\n\r\n",
                              "GET /healthz HTTP/1.1\r\nBad Header Line\r\n\r\n"}) {
    SCOPED_TRACE(garbage);
    HttpClient client(port());
    client.send(garbage);
    HttpResponse r = client.readResponse();
    EXPECT_EQ(r.status, 400);
    EXPECT_EQ(errorCode(r), "invalid_request");
    EXPECT_TRUE(client.peerClosed()) << "a connection whose framing is lost is closed";
  }
  EXPECT_EQ(get(port(), "/healthz").status, 200);
}

TEST_F(ServerTest, OversizedHeaderGets431Json) {
  HttpClient client(port());
  client.send("GET /healthz HTTP/1.1\r\nHost: x\r\nX-Big: " + std::string(64 * 1024, 'a') +
              "\r\n\r\n");
  HttpResponse r = client.readResponse();
  EXPECT_EQ(r.status, 431);
  EXPECT_EQ(errorCode(r), "too_large");
  EXPECT_EQ(get(port(), "/healthz").status, 200);
}

TEST_F(ServerTest, KeepAliveServesSeveralRequestsOnOneConnection) {
  HttpClient client(port());
  HttpResponse first = client.request("GET", "/healthz");
  EXPECT_EQ(first.status, 200);
  EXPECT_NE(first.header("Connection"), "close");
  HttpResponse second = client.request("POST", "/v1/render", smallRender());
  EXPECT_EQ(second.status, 200);
  HttpResponse third = client.request("GET", "/nothing-here");
  EXPECT_EQ(third.status, 404);
  HttpResponse fourth = client.request("GET", "/readyz");
  EXPECT_EQ(fourth.status, 200);
  EXPECT_FALSE(client.peerClosed(100ms));
}

TEST_F(ServerTest, ExpectContinueGetsTheGoAheadBeforeTheBody) {
  std::string body = smallRender();
  HttpClient client(port());
  client.send(
      "POST /v1/render HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\n"
      "Expect: 100-continue\r\nContent-Length: " +
      std::to_string(body.size()) + "\r\n\r\n");
  HttpResponse interim = client.readResponse();
  EXPECT_EQ(interim.status, 100);
  client.send(body);
  EXPECT_EQ(client.readResponse().status, 200);
}

TEST_F(ServerTest, FiftyConcurrentClientsAllGetTheirRender) {
  constexpr int kClients = 50;
  std::vector<int> statuses(kClients, 0);
  std::vector<std::thread> threads;
  for (int i = 0; i < kClients; ++i) {
    threads.emplace_back([&, i] {
      try {
        statuses[i] = post(port(), "/v1/render", smallRender()).status;
      } catch (const std::exception&) {
        statuses[i] = -1;
      }
    });
  }
  for (auto& t : threads) t.join();
  std::map<int, int> histogram;
  for (int s : statuses) ++histogram[s];
  // The queue (64) holds every one of them: no 429 either.
  EXPECT_EQ(histogram[200], kClients) << "statuses: 200 x" << histogram[200] << ", 429 x "
                                      << histogram[429] << ", failed x" << histogram[-1];
}

// ---- Servers with their own configuration ----

TEST(ServerLimits, BodyOverTheLimitGets413AndTheServerCarriesOn) {
  auto server = ServerProcess::withConfig(R"({"workers": 1, "maxBodyBytes": 2048})");
  // Just over, and far over (the server must not reset the connection under the client's
  // feet while it is still sending: the client reads the 413).
  for (size_t size : {size_t{4096}, size_t{4} << 20}) {
    SCOPED_TRACE(size);
    std::string body = "{\"pad\": \"" + std::string(size, 'x') + "\"}";
    HttpResponse r = post(server.port(), "/v1/render", body);
    EXPECT_EQ(r.status, 413);
    EXPECT_EQ(errorCode(r), "too_large");
    EXPECT_NE(r.body.find("maxBodyBytes"), std::string::npos) << r.body;
  }
  {
    // With Expect: 100-continue the client learns it without sending the body at all.
    HttpClient client(server.port());
    client.send(
        "POST /v1/render HTTP/1.1\r\nHost: x\r\nExpect: 100-continue\r\n"
        "Content-Length: 100000\r\n\r\n");
    HttpResponse r = client.readResponse();
    EXPECT_EQ(r.status, 413);
    EXPECT_EQ(errorCode(r), "too_large");
    EXPECT_TRUE(client.peerClosed());
  }
  EXPECT_EQ(post(server.port(), "/v1/render", smallRender()).status, 200);
  EXPECT_EQ(server.terminate(SIGTERM), 0);
}

TEST(ServerLimits, FullQueueAnswers429WithRetryAfter) {
  auto server = ServerProcess::withConfig(R"({"workers": 1, "queueDepth": 1})");
  constexpr int kClients = 6;
  std::vector<HttpResponse> answers(kClients);
  std::vector<std::thread> threads;
  for (int i = 0; i < kClients; ++i) {
    threads.emplace_back([&, i] { answers[i] = post(server.port(), "/v1/render", slowRender()); });
  }
  for (auto& t : threads) t.join();
  int ok = 0, busy = 0;
  for (const auto& a : answers) {
    if (a.status == 200) ++ok;
    if (a.status == 429) {
      ++busy;
      EXPECT_EQ(errorCode(a), "busy");
      ASSERT_FALSE(a.header("Retry-After").empty());
      EXPECT_GE(std::stoi(a.header("Retry-After")), 1);
    }
  }
  EXPECT_EQ(ok + busy, kClients);
  EXPECT_GE(ok, 1);
  EXPECT_GE(busy, 1) << "one worker and one queue slot cannot take " << kClients << " at once";
  EXPECT_EQ(server.terminate(SIGTERM), 0);
}

// A mesh whose limit surface alone takes tens of seconds to build (40 vertices at valence 500,
// just under limits.maxValence): the 504 comes at the deadline, the worker stops building
// within about a second of it and serves the next request.
TEST(ServerLimits, DeadlineStopsTheLimitSurfaceBuild) {
  auto server = ServerProcess::withConfig(R"({"workers": 1, "requestTimeoutMs": 500})");
  std::string obj;
  const int fans = 40, n = 500;
  for (int fan = 0; fan < fans; ++fan) {
    const int centre = fan * (n + 1) + 1;  // 1-based OBJ indices
    obj += "v " + std::to_string(3 * fan) + " 0 0\\n";
    for (int k = 0; k < n; ++k) {
      double a = 2 * 3.14159265358979 * k / n;
      obj += "v " + std::to_string(3 * fan + std::cos(a)) + " " + std::to_string(std::sin(a)) +
             " 0\\n";
    }
    for (int k = 0; k < n; ++k) {
      obj += "f " + std::to_string(centre) + " " + std::to_string(centre + 1 + k) + " " +
             std::to_string(centre + 1 + (k + 1) % n) + "\\n";
    }
  }
  std::string body = R"({"mesh": {"format": "obj", "scheme": "loop", "data": ")" + obj +
                     R"("}, "method": "coarse", "outputs": ["color"]})";
  auto start = std::chrono::steady_clock::now();
  HttpResponse r = post(server.port(), "/v1/render", body);
  EXPECT_EQ(r.status, 504) << r.body.substr(0, 300);
  EXPECT_LT(std::chrono::steady_clock::now() - start, 3s);
  int busy = -1;
  for (int i = 0; i < 60 && busy != 0; ++i) {
    busy = parseJson(get(server.port(), "/healthz").body)["busyWorkers"].GetInt();
    if (busy != 0) std::this_thread::sleep_for(50ms);
  }
  EXPECT_EQ(busy, 0) << "the worker is still building the limit surface";
  EXPECT_LT(std::chrono::steady_clock::now() - start, 3s);
  EXPECT_EQ(post(server.port(), "/v1/render", smallRender()).status, 200);
  EXPECT_EQ(server.terminate(SIGTERM), 0);
}

// A configured bearer token guards the /v1 routes and nothing else; configured origins get CORS
// headers on every answer and a 204 to their preflights, which carry no token.
TEST(ServerAccess, BearerTokenAndCors) {
  auto server = ServerProcess::withConfig(
      R"({"workers": 1, "authToken": "s3cret-token", "corsOrigins": ["http://localhost:5173"]})");
  const int port = server.port();
  HttpResponse none = post(port, "/v1/render", smallRender());
  EXPECT_EQ(none.status, 401);
  EXPECT_EQ(errorCode(none), "unauthorized");
  EXPECT_EQ(none.header("WWW-Authenticate"), "Bearer");
  HttpResponse wrong =
      post(port, "/v1/render", smallRender(), {{"Authorization", "Bearer s3cret-tokeX"}});
  EXPECT_EQ(wrong.status, 401);
  EXPECT_EQ(post(port, "/v1/silhouette", smallRender()).status, 401);
  HttpResponse right =
      post(port, "/v1/render", smallRender(), {{"Authorization", "Bearer s3cret-token"}});
  EXPECT_EQ(right.status, 200) << right.body.substr(0, 200);
  for (const char* open : {"/healthz", "/readyz", "/metrics", "/openapi.json"}) {
    EXPECT_EQ(get(port, open).status, 200) << open;
  }

  HttpClient client(port);
  HttpResponse preflight =
      client.request("OPTIONS", "/v1/render", "",
                     {{"Origin", "http://localhost:5173"},
                      {"Access-Control-Request-Method", "POST"},
                      {"Access-Control-Request-Headers", "authorization, content-type"}});
  EXPECT_EQ(preflight.status, 204);
  EXPECT_EQ(preflight.header("Access-Control-Allow-Origin"), "http://localhost:5173");
  EXPECT_NE(preflight.header("Access-Control-Allow-Headers").find("Authorization"),
            std::string::npos);
  EXPECT_NE(preflight.header("Access-Control-Allow-Methods").find("POST"), std::string::npos);
  HttpResponse cors = client.request(
      "POST", "/v1/render", smallRender(),
      {{"Origin", "http://localhost:5173"}, {"Authorization", "Bearer s3cret-token"}});
  EXPECT_EQ(cors.status, 200);
  EXPECT_EQ(cors.header("Access-Control-Allow-Origin"), "http://localhost:5173");
  // Refusals carry the header too, so the page can read why.
  HttpResponse refusedCors =
      client.request("POST", "/v1/render", smallRender(), {{"Origin", "http://localhost:5173"}});
  EXPECT_EQ(refusedCors.status, 401);
  EXPECT_EQ(refusedCors.header("Access-Control-Allow-Origin"), "http://localhost:5173");
  HttpResponse stranger =
      client.request("OPTIONS", "/v1/render", "", {{"Origin", "http://elsewhere.example"}});
  EXPECT_NE(stranger.status, 204);
  EXPECT_FALSE(stranger.has("Access-Control-Allow-Origin"));
  EXPECT_EQ(server.terminate(SIGTERM), 0);
}

TEST(ServerLimits, RequestTimeoutGets504AndFreesTheWorker) {
  auto server = ServerProcess::withConfig(R"({"workers": 1, "requestTimeoutMs": 1})");
  auto start = std::chrono::steady_clock::now();
  HttpResponse r = post(server.port(), "/v1/render", slowRender());
  EXPECT_EQ(r.status, 504) << r.body.substr(0, 300);
  EXPECT_EQ(errorCode(r), "timeout");
  EXPECT_LT(std::chrono::steady_clock::now() - start, 5s);
  // The worker notices its cancelled token and becomes free again.
  int busy = -1;
  for (int i = 0; i < 200 && busy != 0; ++i) {
    auto doc = parseJson(get(server.port(), "/healthz").body);
    busy = doc["busyWorkers"].GetInt();
    if (busy != 0) std::this_thread::sleep_for(50ms);
  }
  EXPECT_EQ(busy, 0);
  EXPECT_EQ(server.terminate(SIGTERM), 0);
}

TEST(ServerShutdown, SigtermWhileARenderIsInFlightAnswersItAndExitsCleanly) {
  auto server = ServerProcess::withConfig(R"({"workers": 1})");
  std::atomic<int> status{0};
  std::thread client([&] {
    try {
      status = post(server.port(), "/v1/render", slowRender()).status;
    } catch (const std::exception&) {
      status = -1;
    }
  });
  // Wait until the render is really running.
  for (int i = 0; i < 400; ++i) {
    auto doc = parseJson(get(server.port(), "/healthz").body);
    if (doc["busyWorkers"].GetInt() > 0) break;
    std::this_thread::sleep_for(5ms);
  }
  EXPECT_EQ(server.terminate(SIGTERM), 0);
  client.join();
  EXPECT_TRUE(status == 200 || status == 503) << "status " << status;
}

// SIGTERM under load: the connection backlog is closed at once, every request already sent gets
// an answer - 200 for the ones that finish within shutdownDrainMs, 503 for the rest - and the
// process exits soon after the drain deadline. The drain and the load come from one render
// timed first on this machine, so that the queue holds several drains' worth of work however
// fast or loaded the machine is.
TEST(ServerShutdown, SigtermUnderLoadDrainsAnswersEveryoneAndExitsInBoundedTime) {
  std::chrono::milliseconds render{0};
  {
    auto probe = ServerProcess::withConfig(R"({"workers": 1})");
    post(probe.port(), "/v1/render", slowRender());  // the first one warms the worker
    const auto start = std::chrono::steady_clock::now();
    ASSERT_EQ(post(probe.port(), "/v1/render", slowRender()).status, 200);
    render = std::chrono::duration_cast<std::chrono::milliseconds>(
        std::chrono::steady_clock::now() - start);
  }
  // The render running at the signal has three render times left to finish in; twelve renders
  // queued need four times the drain.
  const auto drain = std::max(3 * render, std::chrono::milliseconds(300));
  constexpr int kClients = 12;
  // (The heavy lane's budget is lifted: all twelve must be queued, whatever they are estimated.)
  auto server = ServerProcess::withConfig(
      R"({"workers": 1, "queueDepth": 16, "heavyQueueMs": 86400000, "shutdownDrainMs": )" +
      std::to_string(drain.count()) + "}");
  const int port = server.port();
  // Warm this server's worker as the probe's was: a cold worker's first render (its GL context,
  // llvmpipe's shaders) can take several warm renders' time, and it would be the one running at
  // the signal.
  ASSERT_EQ(post(port, "/v1/render", slowRender()).status, 200);
  std::vector<int> statuses(kClients, 0);
  std::vector<std::thread> clients;
  for (int i = 0; i < kClients; ++i) {
    clients.emplace_back([&, i] {
      try {
        statuses[i] = post(port, "/v1/render", slowRender()).status;
      } catch (const std::exception&) {
        statuses[i] = -1;  // connection dropped without an answer
      }
    });
  }
  for (int i = 0; i < 1000; ++i) {
    auto doc = parseJson(get(port, "/healthz").body);
    if (doc["busyWorkers"].GetInt() > 0 && doc["queueDepth"].GetInt() >= kClients - 2) break;
    std::this_thread::sleep_for(5ms);
  }
  const auto start = std::chrono::steady_clock::now();
  int exitStatus = -2;
  std::thread terminating([&] { exitStatus = server.terminate(SIGTERM); });
  std::this_thread::sleep_for(std::min(drain / 2, std::chrono::milliseconds(300)));
  EXPECT_THROW(HttpClient late(port), std::exception) << "new connections must be refused";
  terminating.join();
  const auto elapsed = std::chrono::steady_clock::now() - start;
  for (auto& c : clients) c.join();
  EXPECT_EQ(exitStatus, 0);
  // The drain, then the cancelled render's stop (well within a second) and the exit.
  EXPECT_LT(elapsed, drain + render + 3s) << "render " << render.count() << " ms";
  int finished = 0, refused = 0;
  for (int status : statuses) {
    EXPECT_TRUE(status == 200 || status == 503) << "status " << status;
    finished += status == 200;
    refused += status == 503;
  }
  EXPECT_GE(finished, 1) << "the render running at the signal fits the drain";
  EXPECT_GE(refused, 1) << kClients << " renders of " << render.count()
                        << " ms cannot fit a drain of " << drain.count() << " ms";
}

TEST(ServerShutdown, SigintIsACleanShutdownToo) {
  ServerProcess server;
  HttpClient idle(server.port());  // an idle keep-alive connection must not hold it up
  EXPECT_EQ(idle.request("GET", "/healthz").status, 200);
  auto start = std::chrono::steady_clock::now();
  EXPECT_EQ(server.terminate(SIGINT), 0);
  EXPECT_LT(std::chrono::steady_clock::now() - start, 5s);
  EXPECT_TRUE(idle.peerClosed());
}

}  // namespace
}  // namespace limn::testing
