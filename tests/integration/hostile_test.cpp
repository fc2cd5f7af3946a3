// Hostile input through the real `limn serve`, one class at a time: every numeric field given
// NaN-like, infinite, enormous and negative values, JSON nested a million deep, huge faces and
// high valences, and a request over each configured limit. Each must be answered with its 4xx
// JSON error naming what is wrong, well within the request deadline, and the next good request
// must still be answered 200.
#include <gtest/gtest.h>
#include <rapidjson/document.h>

#include <chrono>
#include <cmath>
#include <string>
#include <vector>

#include "tests/integration/http_client.h"
#include "tests/integration/server_process.h"

namespace limn::testing {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

// Small limits so that a request just over each of them is cheap to make and to refuse.
constexpr const char* kConfig = R"({"workers": 2, "requestTimeoutMs": 10000,
  "limits": {"maxVertices": 2000, "maxFaces": 1000, "maxFaceSize": 64, "maxValence": 64,
             "maxImageSide": 512, "maxSupersample": 4, "maxSupersampledPixels": 1048576, "maxLevel": 4, "minDicingRate": 0.5,
             "maxSearchSteps": 10, "maxCurveSamples": 64, "maxTriangles": 200000}})";

const char* kCubePoints =
    "[[-1,-1,1],[1,-1,1],[-1,1,1],[1,1,1],[-1,1,-1],[1,1,-1],[-1,-1,-1],[1,-1,-1]]";

// A cube in the JSON mesh form; "@" in any part stands for the value under test.
std::string cubeRequest(const std::string& meshExtra = "", const std::string& extra = "",
                        const std::string& points = kCubePoints,
                        const std::string& camera = R"({"width": 64, "height": 64})") {
  return R"({"mesh": {"points": )" + points +
         R"(, "faceVertexCounts": [4,4,4,4,4,4], "faceVertexIndices": [0,1,3,2, 2,3,5,4,
          4,5,7,6, 6,7,1,0, 1,7,5,3, 6,0,2,4])" +
         meshExtra + R"(}, "camera": )" + camera + extra + "}";
}

std::string replaceAt(std::string text, const std::string& value) {
  const size_t at = text.find('@');
  return at == std::string::npos ? text : text.replace(at, 1, value);
}

struct Refusal {
  int status = 0;
  std::string code, body;
};

class HostileInput : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { server_ = new ServerProcess(ServerProcess::withConfig(kConfig)); }
  static void TearDownTestSuite() {
    delete server_;
    server_ = nullptr;
  }
  static int port() { return server_->port(); }

  // Posts `body`, checks it was answered within `within` with a JSON error, then that the
  // server still renders a good request.
  static Refusal refuse(const std::string& path, const std::string& body,
                        std::chrono::milliseconds within = 5000ms) {
    const auto start = Clock::now();
    HttpResponse r = post(port(), path, body);
    EXPECT_LT(Clock::now() - start, within) << body.substr(0, 200);
    Refusal refusal{r.status, "", r.body};
    rapidjson::Document doc;
    doc.Parse(r.body.c_str(), r.body.size());
    if (!doc.HasParseError() && doc.IsObject() && doc.HasMember("error") &&
        doc["error"].IsObject() && doc["error"].HasMember("code")) {
      refusal.code = doc["error"]["code"].GetString();
    }
    EXPECT_EQ(r.header("Content-Type"), "application/json") << r.body.substr(0, 200);
    EXPECT_EQ(post(port(), "/v1/render", cubeRequest()).status, 200)
        << "the server stopped serving after " << body.substr(0, 200);
    return refusal;
  }

  static ServerProcess* server_;
};

ServerProcess* HostileInput::server_ = nullptr;

// Every numeric field of a render request, with "@" where the value goes.
const std::vector<std::string>& numericFields() {
  static const std::vector<std::string> fields = {
      cubeRequest("", "",
                  "[[@,-1,1],[1,-1,1],[-1,1,1],[1,1,1],[-1,1,-1],[1,1,-1],[-1,-1,-1],[1,-1,-1]]"),
      cubeRequest(R"(, "creaseIndices": [0,1], "creaseLengths": [2], "creaseSharpnesses": [@])"),
      cubeRequest(R"(, "cornerIndices": [0], "cornerSharpnesses": [@])"),
      cubeRequest(R"(, "holeIndices": [@])"),
      cubeRequest("", "", kCubePoints, R"({"width": @})"),
      cubeRequest("", "", kCubePoints, R"({"height": @})"),
      cubeRequest("", "", kCubePoints, R"({"eye": [0, 0, @]})"),
      cubeRequest("", "", kCubePoints, R"({"target": [@, 0, 0]})"),
      cubeRequest("", "", kCubePoints, R"({"up": [0, @, 0]})"),
      cubeRequest("", "", kCubePoints, R"({"fovYDeg": @})"),
      cubeRequest("", "", kCubePoints, R"({"projection": "orthographic", "orthoHeight": @})"),
      cubeRequest("", R"(, "method": "uniform", "params": {"level": @})"),
      cubeRequest("", R"(, "params": {"dicingRate": @})"),
      cubeRequest("", R"(, "reference": true, "params": {"metricSupersample": @})"),
      cubeRequest("", R"(, "method": "silhouette", "params": {"searchSteps": @})"),
      cubeRequest("", R"(, "method": "silhouette", "params": {"curveSamples": @})"),
      cubeRequest("", R"(, "method": "silhouette", "params": {"presubdivide": @})"),
  };
  return fields;
}

// JSON has no NaN or Infinity: those, numbers past a double's range and malformed numbers are
// 400 invalid_json; finite but absurd values are 400/413/422 naming the field. Never a 500,
// never a 200 with a picture made of garbage, never a hang.
TEST_F(HostileInput, EveryNumericFieldRefusesNaNInfinityAndAbsurdValues) {
  for (const std::string& field : numericFields()) {
    for (const char* value :
         {"NaN", "Infinity", "-Infinity", "1e999", "-1e999", "1e308", "-1e308",
          "99999999999999999999", "-2147483649", "\"12\"", "null", "1.5e-320", "0x10"}) {
      SCOPED_TRACE(std::string(value) + " in " + field.substr(0, 160));
      Refusal r = refuse("/v1/render", replaceAt(field, value));
      // NaN, Infinity, 1e999 and 0x10 are not JSON numbers; "12" and null are not numbers.
      const bool notANumber = std::string(value).find_first_of("NI\"nx") != std::string::npos ||
                              std::string(value).find("e999") != std::string::npos;
      if (!notANumber && r.status == 200) continue;  // e.g. a sharpness of 1e20: infinitely sharp
      EXPECT_GE(r.status, 400) << r.body.substr(0, 300);
      EXPECT_LT(r.status, 500) << r.body.substr(0, 300);
      EXPECT_FALSE(r.code.empty()) << r.body.substr(0, 300);
    }
  }
}

// Finite but absurd: a vertex at 1e308 (its bounding box overflows), a camera 1e20 away from a
// mesh of size 2, a field of view of 1e-320 degrees, an orthographic view 1e308 high. Each is a
// 4xx naming its field, not a blank picture or a tessellation estimated from infinities.
TEST_F(HostileInput, AbsurdButFiniteCoordinatesAndCamerasAreRefusedByName) {
  struct Case {
    std::string field, body;
    int status;
  };
  const std::vector<Case> cases = {
      {"vertex 0",
       cubeRequest("", "",
                   "[[1e308,-1,1],[1,-1,1],[-1,1,1],[1,1,1],[-1,1,-1],[1,1,-1],"
                   "[-1,-1,-1],[1,-1,-1]]"),
       422},
      {"camera.eye", cubeRequest("", "", kCubePoints, R"({"eye": [0, 0, 1e20]})"), 400},
      {"camera.target", cubeRequest("", "", kCubePoints, R"({"target": [1e20, 0, 0]})"), 400},
      {"camera.fovYDeg", cubeRequest("", "", kCubePoints, R"({"fovYDeg": 1.5e-320})"), 400},
      {"camera.orthoHeight",
       cubeRequest("", "", kCubePoints, R"({"projection": "orthographic", "orthoHeight": 1e308})"),
       400},
      {"camera.orthoHeight",
       cubeRequest("", "", kCubePoints, R"({"projection": "orthographic", "orthoHeight": 1e-300})"),
       400},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.field);
    for (const char* path : {"/v1/render", "/v1/silhouette"}) {
      Refusal r = refuse(path, c.body);
      EXPECT_EQ(r.status, c.status) << path << ": " << r.body.substr(0, 300);
      EXPECT_NE(r.body.find(c.field), std::string::npos) << path << ": " << r.body.substr(0, 300);
    }
  }
}

// Numbers that RapidJSON 1.1.0's full-precision conversion read out of bounds on, crashing the
// whole server with one request (found by fuzz/json_mesh): now read by its default conversion.
TEST_F(HostileInput, NumbersThatCrashedTheJsonParserAreRead) {
  for (const char* number :
       {"0.00000000017994409662966923262e-320",
        "199999959999999999999000000000002000000002000000000000000000000000000000000001e-320",
        "1e-99999999999", "-0.000000000000000000000000000000000000000000000000000001e-300"}) {
    SCOPED_TRACE(number);
    const std::string points = std::string("[[") + number +
                               ",-1,1],[1,-1,1],[-1,1,1],[1,1,1],[-1,1,-1],[1,1,-1],[-1,-1,-1],"
                               "[1,-1,-1]]";
    for (const char* path : {"/v1/render", "/v1/silhouette"}) {
      HttpResponse r = post(port(), path, cubeRequest("", "", points));
      EXPECT_EQ(r.status, 200) << path << ": " << r.body.substr(0, 300);
    }
  }
}

// The same values in the OBJ form: the line is named.
TEST_F(HostileInput, ObjCoordinatesAndSharpnessesThatAreNotFiniteNameTheLine) {
  for (const char* value :
       {"nan", "-nan", "inf", "-inf", "infinity", "1e999", "0x1p3", "1e-999x"}) {
    SCOPED_TRACE(value);
    const std::string obj =
        std::string("v 0 0 0\\nv 1 0 0\\nv 1 1 ") + value + "\\nv 0 1 0\\nf 1 2 3 4\\n";
    Refusal r = refuse("/v1/render", R"({"mesh": {"format": "obj", "data": ")" + obj + "\"}}");
    EXPECT_EQ(r.status, 422) << r.body;
    EXPECT_NE(r.body.find("line 3"), std::string::npos) << r.body;
  }
  const std::string creased =
      "v 0 0 0\\nv 1 0 0\\nv 1 1 0\\nv 0 1 0\\nf 1 2 3 4\\nt crease 2/1/0 0 1 nan\\n";
  Refusal r = refuse("/v1/render", R"({"mesh": {"format": "obj", "data": ")" + creased + "\"}}");
  EXPECT_EQ(r.status, 422) << r.body;
  EXPECT_NE(r.body.find("line 6"), std::string::npos) << r.body;
}

// A million nested arrays (2 MB): parsed without recursion, refused where a mesh or the whole
// body should be, ignored with a warning in a field limn does not know - never a stack
// overflow, in the parser or when the document is freed.
TEST_F(HostileInput, DeepJsonNestingIsRefusedWithoutExhaustingTheStack) {
  constexpr size_t kDepth = 1'000'000;
  const std::string nested = std::string(kDepth, '[') + std::string(kDepth, ']');
  for (const char* path : {"/v1/render", "/v1/silhouette"}) {
    SCOPED_TRACE(path);
    for (const std::string& body : {R"({"mesh": )" + nested + "}", std::string(kDepth, '[')}) {
      Refusal r = refuse(path, body);
      EXPECT_EQ(r.status, 400) << r.body.substr(0, 300);
      EXPECT_TRUE(r.code == "invalid_json" || r.code == "invalid_request") << r.code;
    }
    const auto start = Clock::now();
    HttpResponse ignored = post(port(), path, cubeRequest("", R"(, "extra": )" + nested));
    EXPECT_LT(Clock::now() - start, 5s);
    EXPECT_EQ(ignored.status, 200) << ignored.body.substr(0, 300);
    EXPECT_NE(ignored.body.find("extra"), std::string::npos) << "the warning names the field";
  }
}

// A single face with 1,500 vertices, a face at the limit, a face of two vertices, and a vertex
// shared by more faces than maxValence. (A face that repeats a vertex is not refused:
// OpenSubdiv renders it as non-manifold, and its own regression shapes have such faces.)
TEST_F(HostileInput, HugeFacesAndHighValencesAreRefusedByName) {
  auto polygon = [](int n) {
    std::string points = "[", counts = "[" + std::to_string(n) + "]", indices = "[";
    for (int i = 0; i < n; ++i) {
      const double a = 6.283185307179586 * i / n;
      points += (i ? ",[" : "[") + std::to_string(std::cos(a)) + "," + std::to_string(std::sin(a)) +
                ",0]";
      indices += (i ? "," : "") + std::to_string(i);
    }
    return R"({"mesh": {"points": )" + points + "], \"faceVertexCounts\": " + counts +
           ", \"faceVertexIndices\": " + indices +
           "]}, \"camera\": {\"width\": 64, \"height\": 64}}";
  };
  Refusal huge = refuse("/v1/render", polygon(1500));
  EXPECT_EQ(huge.status, 413) << huge.body.substr(0, 300);
  EXPECT_NE(huge.body.find("maxFaceSize"), std::string::npos) << huge.body.substr(0, 300);
  EXPECT_EQ(post(port(), "/v1/render", polygon(64)).status, 200) << "a face at the limit renders";

  Refusal twoSided = refuse("/v1/render", R"({"mesh": {"points": [[0,0,0],[1,0,0]],
      "faceVertexCounts": [2], "faceVertexIndices": [0,1]}})");
  EXPECT_GE(twoSided.status, 400) << twoSided.body.substr(0, 300);
  EXPECT_LT(twoSided.status, 500) << twoSided.body.substr(0, 300);
  EXPECT_NE(twoSided.body.find("face 0"), std::string::npos) << twoSided.body.substr(0, 300);

  // A fan of 100 triangles around vertex 0 (limit 64).
  std::string points = "[[0,0,0]", indices;
  for (int i = 0; i < 100; ++i) {
    const double a = 6.283185307179586 * i / 100;
    points += ",[" + std::to_string(std::cos(a)) + "," + std::to_string(std::sin(a)) + ",0]";
    indices += (i ? "," : "") + std::string("0,") + std::to_string(1 + i) + "," +
               std::to_string(1 + (i + 1) % 100);
  }
  std::string counts = "[3";
  for (int i = 1; i < 100; ++i) counts += ",3";
  Refusal fan = refuse("/v1/render", R"({"mesh": {"scheme": "loop", "points": )" + points +
                                         "], \"faceVertexCounts\": " + counts +
                                         "], \"faceVertexIndices\": [" + indices + "]}}");
  EXPECT_EQ(fan.status, 422) << fan.body.substr(0, 300);
  EXPECT_NE(fan.body.find("vertex 0"), std::string::npos) << fan.body.substr(0, 300);
  EXPECT_NE(fan.body.find("maxValence"), std::string::npos) << fan.body.substr(0, 300);
}

// One request just over each configured limit: 413 too_large (or 400 for a parameter range)
// naming the limit, before any of the cost is paid.
TEST_F(HostileInput, ARequestOverEachLimitIsRefusedNamingIt) {
  auto grid = [](int n) {  // n x n quads: (n+1)^2 vertices, n^2 faces
    std::string points, counts, indices;
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i)
        points +=
            (points.empty() ? "[" : ",[") + std::to_string(i) + "," + std::to_string(j) + ",0]";
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const int v = j * (n + 1) + i;
        counts += counts.empty() ? "4" : ",4";
        indices += (indices.empty() ? "" : ",") + std::to_string(v) + "," + std::to_string(v + 1) +
                   "," + std::to_string(v + n + 2) + "," + std::to_string(v + n + 1);
      }
    return R"({"mesh": {"points": [)" + points + "], \"faceVertexCounts\": [" + counts +
           "], \"faceVertexIndices\": [" + indices +
           "]}, \"camera\": {\"width\": 64, \"height\": 64}";
  };
  struct Case {
    const char* limit;
    std::string body;
  };
  std::string manyPoints = "[";
  for (int i = 0; i < 2001; ++i) manyPoints += (i ? ",[" : "[") + std::to_string(i % 7) + ",1,2]";
  manyPoints += "]";
  const std::vector<Case> cases = {
      {"maxVertices", cubeRequest("", "", manyPoints)},  // 2001 points, 6 faces
      {"maxFaces", grid(32) + "}"},                      // 1089 vertices, 1024 faces
      {"maxImageSide", cubeRequest("", "", kCubePoints, R"({"width": 513, "height": 64})")},
      {"maxSupersample",
       cubeRequest("", R"(, "reference": true, "params": {"metricSupersample": 5})")},
      {"maxLevel", cubeRequest("", R"(, "method": "uniform", "params": {"level": 5})")},
      // 512^2 at S = 4 is 4M mask samples; the limit is 1M (256^2 at S = 4 fits).
      {"maxSupersampledPixels",
       cubeRequest("", R"(, "reference": true, "params": {"metricSupersample": 4})", kCubePoints,
                   R"({"width": 512, "height": 512})")},
      {"minDicingRate", cubeRequest("", R"(, "params": {"dicingRate": 0.25})")},
      {"maxSearchSteps",
       cubeRequest("", R"(, "method": "silhouette", "params": {"searchSteps": 11})")},
      {"maxCurveSamples",
       cubeRequest("", R"(, "method": "silhouette", "params": {"curveSamples": 65})")},
      // 6 * 4^4 * 2 = 12k triangles fit; a 30 x 30 grid at level 4 is 460k.
      {"maxTriangles", grid(30) + R"(, "method": "uniform", "params": {"level": 4}})"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.limit);
    for (const char* path : {"/v1/render", "/v1/silhouette"}) {
      if (std::string(path) == "/v1/silhouette" && std::string(c.limit) != "maxVertices" &&
          std::string(c.limit) != "maxFaces" && std::string(c.limit) != "maxSearchSteps" &&
          std::string(c.limit) != "maxCurveSamples") {
        continue;  // the contour search has no images, levels or triangles to bound
      }
      SCOPED_TRACE(path);
      Refusal r = refuse(path, c.body, 2000ms);
      EXPECT_TRUE(r.status == 413 || r.status == 400) << r.body.substr(0, 300);
      EXPECT_NE(r.body.find(c.limit), std::string::npos) << r.body.substr(0, 300);
    }
  }
}

}  // namespace
}  // namespace limn::testing
