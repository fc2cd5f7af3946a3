// POST /v1/silhouette through the real `limn serve` process: the contour of a cube as one
// closed, fully visible polyline on the limit surface's contour; the same answer as SVG through
// the Accept header and through "format"; self-occlusion (a blob in front of another, and a
// torus seen from a low angle) with the covered outline marked hidden; bad requests answered
// 400 JSON naming the field while the server carries on.
#include <gtest/gtest.h>
#include <rapidjson/document.h>

#include <cmath>
#include <csignal>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "render/subdiv/limit_surface.h"
#include "tests/integration/http_client.h"
#include "tests/integration/json_answer.h"
#include "tests/integration/server_process.h"
#include "tests/support/random_views.h"
#include "tests/support/shapes.h"

namespace limn::testing {
namespace {

// A unit cube as OBJ text with JSON-escaped newlines.
const char* kCubeObj =
    "v -1 -1 1\\nv 1 -1 1\\nv -1 1 1\\nv 1 1 1\\nv -1 1 -1\\nv 1 1 -1\\nv -1 -1 -1\\nv 1 -1 -1\\n"
    "f 1 2 4 3\\nf 3 4 6 5\\nf 5 6 8 7\\nf 7 8 2 1\\nf 2 8 6 4\\nf 7 1 3 5\\n";

const char* kObliqueCamera =
    R"("camera": {"eye": [2.5, 1.8, 4.0], "target": [0, 0, 0], "width": 256, "height": 256})";

std::string cubeRequest(const std::string& extra = "", const std::string& camera = kObliqueCamera) {
  return std::string(R"({"mesh": {"format": "obj", "data": ")") + kCubeObj + "\"}, " + camera +
         extra + "}";
}

// Two cubes of side 1 in one JSON mesh, the first moved by `a`, the second by `b`.
std::string twoCubesMesh(const double a[3], const double b[3]) {
  const int corners[8][3] = {{-1, -1, 1}, {1, -1, 1}, {-1, 1, 1},   {1, 1, 1},
                             {-1, 1, -1}, {1, 1, -1}, {-1, -1, -1}, {1, -1, -1}};
  const int faces[6][4] = {{0, 1, 3, 2}, {2, 3, 5, 4}, {4, 5, 7, 6},
                           {6, 7, 1, 0}, {1, 7, 5, 3}, {6, 0, 2, 4}};
  std::ostringstream out;
  out << R"({"points": [)";
  for (int c = 0; c < 2; ++c) {
    const double* o = c == 0 ? a : b;
    for (int i = 0; i < 8; ++i) {
      out << (c + i ? "," : "") << "[" << o[0] + 0.5 * corners[i][0] << ","
          << o[1] + 0.5 * corners[i][1] << "," << o[2] + 0.5 * corners[i][2] << "]";
    }
  }
  out << R"(], "faceVertexCounts": [4,4,4,4,4,4,4,4,4,4,4,4], "faceVertexIndices": [)";
  for (int c = 0; c < 2; ++c) {
    for (int f = 0; f < 6; ++f) {
      for (int k = 0; k < 4; ++k) out << (c + f + k ? "," : "") << faces[f][k] + 8 * c;
    }
  }
  out << "]}";
  return out.str();
}

// A smooth torus in the xy plane (ring radius 1, tube 0.35) as a JSON mesh.
std::string torusMesh(int ring = 24, int tube = 12) {
  std::ostringstream out;
  out << R"({"points": [)";
  for (int i = 0; i < ring; ++i) {
    for (int j = 0; j < tube; ++j) {
      double a = 2 * std::numbers::pi * i / ring, b = 2 * std::numbers::pi * j / tube;
      out << (i + j ? "," : "") << "[" << (1 + 0.35 * std::cos(b)) * std::cos(a) << ","
          << (1 + 0.35 * std::cos(b)) * std::sin(a) << "," << 0.35 * std::sin(b) << "]";
    }
  }
  out << R"(], "faceVertexCounts": [)";
  for (int f = 0; f < ring * tube; ++f) out << (f ? "," : "") << 4;
  out << R"(], "faceVertexIndices": [)";
  auto id = [&](int i, int j) { return (i % ring) * tube + (j % tube); };
  for (int i = 0; i < ring; ++i) {
    for (int j = 0; j < tube; ++j) {
      out << (i + j ? "," : "") << id(i, j) << "," << id(i + 1, j) << "," << id(i + 1, j + 1) << ","
          << id(i, j + 1);
    }
  }
  out << "]}";
  return out.str();
}

size_t count(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

// A point of the answer, as read back.
struct Point {
  double x, y, z;     // position
  double px, py;      // pixel
  double nx, ny, nz;  // normal
  bool visible;
};

std::vector<Point> pointsOf(const rapidjson::Value& polyline) {
  std::vector<Point> out;
  for (const auto& p : polyline["points"].GetArray()) {
    out.push_back({p["position"][0].GetDouble(), p["position"][1].GetDouble(),
                   p["position"][2].GetDouble(), p["pixel"][0].GetDouble(),
                   p["pixel"][1].GetDouble(), p["normal"][0].GetDouble(),
                   p["normal"][1].GetDouble(), p["normal"][2].GetDouble(), p["visible"].GetBool()});
  }
  return out;
}

// Even-odd test of a pixel against a closed polyline's projection, and the pixel's distance
// to it.
bool inside(const std::vector<Point>& loop, double x, double y) {
  bool in = false;
  for (size_t i = 0, j = loop.size() - 1; i < loop.size(); j = i++) {
    const Point &a = loop[i], &b = loop[j];
    if ((a.py > y) != (b.py > y) && x < (b.px - a.px) * (y - a.py) / (b.py - a.py) + a.px) {
      in = !in;
    }
  }
  return in;
}
double distance(const std::vector<Point>& loop, double x, double y) {
  double best = 1e300;
  for (size_t i = 0, j = loop.size() - 1; i < loop.size(); j = i++) {
    const Point &a = loop[i], &b = loop[j];
    double dx = b.px - a.px, dy = b.py - a.py;
    double t = std::clamp(((x - a.px) * dx + (y - a.py) * dy) / std::max(dx * dx + dy * dy, 1e-30),
                          0.0, 1.0);
    best = std::min(best, std::hypot(a.px + t * dx - x, a.py + t * dy - y));
  }
  return best;
}

class SilhouetteEndpointTest : public ::testing::Test {
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
ServerProcess* SilhouetteEndpointTest::server_ = nullptr;

TEST_F(SilhouetteEndpointTest, CubeContourIsOneClosedVisibleLoopOnTheContour) {
  HttpResponse r = post(port(), "/v1/silhouette", cubeRequest());
  ASSERT_EQ(r.status, 200) << r.body.substr(0, 400);
  EXPECT_EQ(r.header("Content-Type"), "application/json");
  auto doc = parseJson(r.body);
  ASSERT_FALSE(doc.HasParseError());
  const auto& camera = doc["camera"];
  EXPECT_EQ(camera["width"].GetInt(), 256);
  const double eye[3] = {camera["eye"][0].GetDouble(), camera["eye"][1].GetDouble(),
                         camera["eye"][2].GetDouble()};

  ASSERT_EQ(doc["polylines"].Size(), 1u);
  const auto& line = doc["polylines"][0];
  EXPECT_TRUE(line["closed"].GetBool());
  ASSERT_EQ(line["pieces"].Size(), 1u);
  EXPECT_TRUE(line["pieces"][0]["visible"].GetBool());
  std::vector<Point> points = pointsOf(line);
  ASSERT_GT(points.size(), 50u);
  EXPECT_EQ(line["pieces"][0]["start"].GetInt(), 0);
  EXPECT_EQ(line["pieces"][0]["end"].GetInt(), static_cast<int>(points.size()) - 1);
  double worst = 0;
  for (const Point& p : points) {
    EXPECT_TRUE(p.visible);
    EXPECT_GT(p.px, 0);
    EXPECT_LT(p.px, 256);
    EXPECT_GT(p.py, 0);
    EXPECT_LT(p.py, 256);
    // On the contour the normal is perpendicular to the view ray.
    double v[3] = {p.x - eye[0], p.y - eye[1], p.z - eye[2]};
    double len = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    worst = std::max(worst, std::fabs(p.nx * v[0] + p.ny * v[1] + p.nz * v[2]) / len);
  }
  EXPECT_LT(worst, 0.01) << "largest |cos| between a contour normal and its view ray";
  // The loop goes round the cube's projection: its pixels span a good part of the image.
  double minX = 1e9, maxX = -1e9;
  for (const Point& p : points) minX = std::min(minX, p.px), maxX = std::max(maxX, p.px);
  EXPECT_GT(maxX - minX, 60);

  const auto& stats = doc["stats"];
  EXPECT_EQ(stats["polylines"].GetInt(), 1);
  EXPECT_EQ(stats["closedPolylines"].GetInt(), 1);
  EXPECT_EQ(stats["points"].GetInt(), static_cast<int>(points.size()));
  EXPECT_EQ(stats["visiblePieces"].GetInt(), 1);
  EXPECT_EQ(stats["hiddenPieces"].GetInt(), 0);
  EXPECT_GT(stats["referenceTriangles"].GetInt(), 1000);
  EXPECT_GT(stats["silhouette"]["contourPoints"].GetInt(), 4);
  EXPECT_GT(doc["timings"]["totalMs"].GetDouble(), 0);
  EXPECT_TRUE(doc["warnings"].IsArray());
}

TEST_F(SilhouetteEndpointTest, SvgByAcceptHeaderOrFormatField) {
  HttpResponse json = post(port(), "/v1/silhouette", cubeRequest());
  ASSERT_EQ(json.status, 200);
  auto doc = parseJson(json.body);
  int visible = doc["stats"]["visiblePieces"].GetInt();
  int hidden = doc["stats"]["hiddenPieces"].GetInt();

  HttpResponse byAccept =
      post(port(), "/v1/silhouette", cubeRequest(), {{"Accept", "image/svg+xml"}});
  HttpResponse byField = post(port(), "/v1/silhouette", cubeRequest(R"(, "format": "svg")"));
  for (const HttpResponse* r : {&byAccept, &byField}) {
    ASSERT_EQ(r->status, 200) << r->body.substr(0, 300);
    EXPECT_EQ(r->header("Content-Type"), "image/svg+xml");
    const std::string& svg = r->body;
    EXPECT_EQ(svg.rfind("<?xml", 0), 0u);
    EXPECT_NE(svg.find(R"(<svg xmlns="http://www.w3.org/2000/svg" width="256" height="256")"),
              std::string::npos);
    EXPECT_EQ(count(svg, "<svg"), 1u);
    EXPECT_EQ(count(svg, "</svg>"), 1u);
    EXPECT_EQ(count(svg, "<path "), static_cast<size_t>(visible + hidden));
    EXPECT_EQ(count(svg, R"(class="visible")"), static_cast<size_t>(visible));
    EXPECT_EQ(count(svg, R"(class="hidden")"), static_cast<size_t>(hidden));
    EXPECT_EQ(count(svg, "/>"), count(svg, "<path ") + 1) << "every path and the rect close";
    // One closed loop: its path ends with Z.
    EXPECT_NE(svg.find(" Z\"/>"), std::string::npos);
  }
  EXPECT_EQ(byAccept.body, byField.body);

  // The field wins over the header; a client preferring JSON gets JSON.
  HttpResponse fieldWins = post(port(), "/v1/silhouette", cubeRequest(R"(, "format": "json")"),
                                {{"Accept", "image/svg+xml"}});
  EXPECT_EQ(fieldWins.header("Content-Type"), "application/json");
  HttpResponse prefersJson = post(port(), "/v1/silhouette", cubeRequest(),
                                  {{"Accept", "image/svg+xml;q=0.5, application/json"}});
  EXPECT_EQ(prefersJson.header("Content-Type"), "application/json");
}

TEST_F(SilhouetteEndpointTest, FarBlobOutlineBehindTheNearBlobIsHidden) {
  // The near blob (z = +1.5) covers part of the far one (z = -1.5) seen from +z.
  const double nearBlob[3] = {0.45, 0.1, 1.5}, farBlob[3] = {0, 0, -1.5};
  std::string body = R"({"mesh": )" + twoCubesMesh(nearBlob, farBlob) +
                     R"(, "camera": {"eye": [0, 0.2, 8], "target": [0, 0, 0], "width": 512, )"
                     R"("height": 512}})";
  HttpResponse r = post(port(), "/v1/silhouette", body);
  ASSERT_EQ(r.status, 200) << r.body.substr(0, 400);
  auto doc = parseJson(r.body);
  ASSERT_EQ(doc["polylines"].Size(), 2u);
  std::vector<Point> nearLoop, farLoop;
  for (const auto& line : doc["polylines"].GetArray()) {
    EXPECT_TRUE(line["closed"].GetBool());
    std::vector<Point> points = pointsOf(line);
    (points[0].z > 0 ? nearLoop : farLoop) = points;
  }
  ASSERT_FALSE(nearLoop.empty());
  ASSERT_FALSE(farLoop.empty());
  for (const Point& p : nearLoop) EXPECT_TRUE(p.visible) << "nothing is in front of the near blob";

  // The inner outline: the far loop's points inside the near loop's projection.
  size_t hidden = 0, innerOutline = 0;
  for (const Point& p : farLoop) {
    bool covered = inside(nearLoop, p.px, p.py);
    innerOutline += covered;
    hidden += !p.visible;
    if (!p.visible) {
      EXPECT_TRUE(covered || distance(nearLoop, p.px, p.py) < 1.0)
          << "hidden point at (" << p.px << ", " << p.py << ") outside the near blob";
    } else {
      EXPECT_TRUE(!covered || distance(nearLoop, p.px, p.py) < 1.0)
          << "visible point at (" << p.px << ", " << p.py << ") behind the near blob";
    }
  }
  EXPECT_GT(innerOutline, 10u) << "contour points on the inner outline";
  EXPECT_GT(hidden, 10u);
  EXPECT_GE(doc["stats"]["hiddenPieces"].GetInt(), 1);
  EXPECT_EQ(doc["stats"]["hiddenPoints"].GetInt(), static_cast<int>(hidden));

  HttpResponse svg = post(port(), "/v1/silhouette", body, {{"Accept", "image/svg+xml"}});
  ASSERT_EQ(svg.status, 200);
  EXPECT_EQ(count(svg.body, R"(class="hidden")"),
            static_cast<size_t>(doc["stats"]["hiddenPieces"].GetInt()));
  EXPECT_EQ(count(svg.body, R"(class="visible")"),
            static_cast<size_t>(doc["stats"]["visiblePieces"].GetInt()));
}

TEST_F(SilhouetteEndpointTest, TorusFromALowAngleHidesPartOfItsInnerOutline) {
  std::string body = R"({"mesh": )" + torusMesh() +
                     R"(, "camera": {"eye": [0, -4.0, 1.1], "target": [0, 0, 0], "width": 512, )"
                     R"("height": 512}, "params": {"contour": "exact"}})";
  HttpResponse r = post(port(), "/v1/silhouette", body);
  ASSERT_EQ(r.status, 200) << r.body.substr(0, 400);
  auto doc = parseJson(r.body);
  ASSERT_GE(doc["polylines"].Size(), 2u) << "the outer outline and the inner one";
  // The outer outline: the polyline reaching furthest out in x.
  size_t outer = 0;
  double reach = 0;
  for (size_t i = 0; i < doc["polylines"].Size(); ++i) {
    for (const Point& p : pointsOf(doc["polylines"][i])) {
      if (std::fabs(p.x) > reach) reach = std::fabs(p.x), outer = i;
    }
  }
  std::vector<Point> outline = pointsOf(doc["polylines"][outer]);
  for (const Point& p : outline) EXPECT_TRUE(p.visible) << "the outer outline is seen whole";
  size_t hiddenInner = 0, visibleInner = 0;
  for (size_t i = 0; i < doc["polylines"].Size(); ++i) {
    if (i == outer) continue;
    for (const Point& p : pointsOf(doc["polylines"][i])) {
      // Every point of the inner outline lies within the torus's projection.
      EXPECT_TRUE(inside(outline, p.px, p.py) || distance(outline, p.px, p.py) < 1.0);
      (p.visible ? visibleInner : hiddenInner) += 1;
    }
  }
  EXPECT_GT(hiddenInner, 10u);
  EXPECT_GT(visibleInner, 10u) << "the far rim of the hole is seen above the near tube";
  EXPECT_GE(doc["stats"]["hiddenPieces"].GetInt(), 1);
}

// The project's sharp-feature meshes and its all-triangle Catmull-Clark sphere through
// POST /v1/render, each from a random view: the outline within a pixel of the exact one.
TEST_F(SilhouetteEndpointTest, SharpAndDenseMeshesFromRandomViewsRenderWithinAPixel) {
  for (const NamedMesh& shape :
       selectShapes(ownShapes(), {"own_sharp_cube", "own_semisharp_cube", "own_chaikin_cube",
                                  "own_sharp_tetrahedron_loop", "own_tri_sphere_1280"})) {
    render::subdiv::LimitSurface surface(shape.mesh);
    RandomView view = randomViews(surface.bounds(), 1, viewSeed(3, shape.name), 256)[0];
    std::string body = R"({"mesh": )" + requestMeshJson(shape.mesh) + R"(, "camera": )" +
                       describeCamera(view.camera) +
                       R"(, "method": "silhouette", "reference": true, "outputs": []})";
    HttpResponse r = post(port(), "/v1/render", body);
    ASSERT_EQ(r.status, 200) << shape.name << ": " << r.body.substr(0, 400);
    auto doc = parseJson(r.body);
    EXPECT_LE(doc["metrics"]["silhouette"]["hausdorffPx"].GetDouble(), 1.0)
        << shape.name << " camera " << describeCamera(view.camera);
    EXPECT_TRUE(doc["stats"]["silhouette"].HasMember("presubdivisionLevels"));
  }
}

TEST_F(SilhouetteEndpointTest, BadRequestsName400FieldsAndTheServerCarriesOn) {
  struct Case {
    const char* name;
    std::string body;
    int status;
    const char* code;
    const char* field;
  };
  const std::vector<Case> cases = {
      {"bad format", cubeRequest(R"(, "format": "png")"), 400, "invalid_request", "format"},
      {"format not a string", cubeRequest(R"(, "format": 3)"), 400, "invalid_request", "format"},
      {"bad contour", cubeRequest(R"(, "params": {"contour": "bezier"})"), 400, "invalid_request",
       "params.contour"},
      {"bad presubdivide", cubeRequest(R"(, "params": {"presubdivide": 2})"), 400,
       "invalid_request", "params.presubdivide"},
      {"searchSteps of the wrong type", cubeRequest(R"(, "params": {"searchSteps": "five"})"), 400,
       "invalid_request", "params.searchSteps"},
      {"params not an object", cubeRequest(R"(, "params": [])"), 400, "invalid_request", "params"},
      {"no mesh", std::string("{") + kObliqueCamera + "}", 400, "invalid_request", "mesh"},
      {"bad camera", cubeRequest("", R"("camera": {"width": "wide"})"), 400, "invalid_request",
       "camera.width"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    HttpResponse r = post(port(), "/v1/silhouette", c.body);
    EXPECT_EQ(r.status, c.status) << r.body.substr(0, 300);
    EXPECT_EQ(r.header("Content-Type"), "application/json");
    EXPECT_EQ(errorField(r), c.field) << r.body.substr(0, 300);
    auto doc = parseJson(r.body);
    ASSERT_TRUE(doc.IsObject() && doc.HasMember("error"));
    EXPECT_STREQ(doc["error"]["code"].GetString(), c.code);
  }
  // Errors stay JSON even when the client asked for SVG.
  HttpResponse svgError =
      post(port(), "/v1/silhouette", "{\"mesh\": ", {{"Accept", "image/svg+xml"}});
  EXPECT_EQ(svgError.status, 400);
  EXPECT_EQ(svgError.header("Content-Type"), "application/json");
  // A mesh the scheme cannot take is 422, an oversized image 413, a GET 405.
  HttpResponse badMesh =
      post(port(), "/v1/silhouette",
           R"({"mesh": {"format": "obj", "data": "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n"}})");
  EXPECT_EQ(badMesh.status, 422);
  HttpResponse tooBig =
      post(port(), "/v1/silhouette", cubeRequest("", R"("camera": {"width": 100000})"));
  EXPECT_EQ(tooBig.status, 413);
  HttpResponse wrongVerb = HttpClient(port()).request("GET", "/v1/silhouette");
  EXPECT_EQ(wrongVerb.status, 405);
  EXPECT_EQ(wrongVerb.header("Allow"), "POST");

  EXPECT_EQ(post(port(), "/v1/silhouette", cubeRequest()).status, 200);
  HttpResponse metrics = get(port(), "/metrics");
  EXPECT_NE(metrics.body.find(R"(limn_requests_total{path="/v1/silhouette",status="200"})"),
            std::string::npos);
  EXPECT_NE(metrics.body.find(R"(limn_requests_total{path="/v1/silhouette",status="400"})"),
            std::string::npos);
}

TEST_F(SilhouetteEndpointTest, OpenApiDocumentDescribesTheEndpoint) {
  HttpResponse r = get(port(), "/openapi.json");
  ASSERT_EQ(r.status, 200);
  auto doc = parseJson(r.body);
  ASSERT_FALSE(doc.HasParseError());
  ASSERT_TRUE(doc["paths"].HasMember("/v1/silhouette"));
  const auto& post = doc["paths"]["/v1/silhouette"]["post"];
  EXPECT_TRUE(post["responses"]["200"]["content"].HasMember("image/svg+xml"));
  EXPECT_TRUE(post["responses"]["200"]["content"].HasMember("application/json"));
  for (const char* schema : {"SilhouetteRequest", "SilhouetteResponse", "ContourPolyline",
                             "ContourPoint", "ContourPiece"}) {
    EXPECT_TRUE(doc["components"]["schemas"].HasMember(schema)) << schema;
  }
}

}  // namespace
}  // namespace limn::testing
