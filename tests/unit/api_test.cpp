// Tests of api/: mesh readers, request parsing with every class of bad input, the response
// shape, base64, the configuration file and the OpenAPI document.
#include <gtest/gtest.h>
#include <rapidjson/document.h>
#include <rapidjson/stringbuffer.h>
#include <rapidjson/writer.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "api/accept.h"
#include "api/base64.h"
#include "api/config.h"
#include "api/json_mesh_reader.h"
#include "api/openapi.h"
#include "api/render_api.h"
#include "api/work_estimate.h"
#include "formats/mesh_writers.h"
#include "formats/obj_reader.h"
#include "render/raster/rasterizer.h"
#include "tests/support/corpus.h"

namespace {

using namespace limn;
using limn::api::ApiError;
using render::InputError;
using render::mesh::BoundaryInterpolation;
using render::mesh::ControlMesh;
using render::mesh::Scheme;
using render::pipeline::JobLimits;

namespace fs = std::filesystem;

// ---------------------------------------------------------------------------------------------
// Helpers

const char* kCubeObj =
    "# unit cube\n"
    "v -1 -1 1\nv 1 -1 1\nv -1 1 1\nv 1 1 1\nv -1 1 -1\nv 1 1 -1\nv -1 -1 -1\nv 1 -1 -1\n"
    "f 1 2 4 3\nf 3 4 6 5\nf 5 6 8 7\nf 7 8 2 1\nf 2 8 6 4\nf 7 1 3 5\n";

const char* kCubeJsonMesh = R"({
  "scheme": "catmull-clark",
  "points": [[-1,-1,1],[1,-1,1],[-1,1,1],[1,1,1],[-1,1,-1],[1,1,-1],[-1,-1,-1],[1,-1,-1]],
  "faceVertexCounts": [4,4,4,4,4,4],
  "faceVertexIndices": [0,1,3,2, 2,3,5,4, 4,5,7,6, 6,7,1,0, 1,7,5,3, 6,0,2,4]})";

std::string jsonString(const std::string& text) {
  rapidjson::StringBuffer buffer;
  rapidjson::Writer<rapidjson::StringBuffer> writer(buffer);
  writer.String(text.c_str(), static_cast<rapidjson::SizeType>(text.size()));
  return buffer.GetString();
}

// A render request with an OBJ mesh and `rest` (more top-level members, with a leading comma).
std::string objRequest(const std::string& obj, const std::string& scheme = "catmull-clark",
                       const std::string& rest = "") {
  return R"({"mesh": {"format": "obj", "scheme": ")" + scheme + R"(", "data": )" + jsonString(obj) +
         "}" + rest + "}";
}

std::string cubeRequest(const std::string& rest) {
  return objRequest(kCubeObj, "catmull-clark", rest);
}

// The ApiError parseRenderRequest throws for `body` (a failure when it accepts the body).
ApiError parseError(const std::string& body, const JobLimits& limits = {}) {
  try {
    api::parseRenderRequest(body, limits);
  } catch (const ApiError& error) {
    return error;
  }
  ADD_FAILURE() << "accepted: " << body.substr(0, 300);
  return {0, "", ""};
}

std::string detailMember(const ApiError& error, const char* key) {
  rapidjson::Document detail;
  detail.Parse(error.detailJson.c_str());
  if (detail.HasParseError() || !detail.IsObject() || !detail.HasMember(key)) return "<absent>";
  const rapidjson::Value& v = detail[key];
  if (v.IsString()) return v.GetString();
  if (v.IsInt64()) return std::to_string(v.GetInt64());
  return "<other>";
}

void expectError(const ApiError& e, int status, const char* code) {
  EXPECT_EQ(e.status, status) << e.message;
  EXPECT_EQ(e.code, code) << e.message;
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

using limn::testing::corpusDir;
std::string readFile(const fs::path& path) { return limn::testing::readTextFile(path); }
Scheme schemeOfCorpusFile(const std::string& name) { return limn::testing::corpusScheme(name); }

formats::ObjMesh readCorpus(const std::string& name) {
  fs::path path = corpusDir() / (name + ".obj");
  if (!fs::exists(path)) throw std::runtime_error("missing corpus file " + path.string());
  return formats::parseObj(readFile(path), schemeOfCorpusFile(name), {});
}

// The InputError readObj throws for `obj`.
InputError objError(const std::string& obj, Scheme scheme = Scheme::CatmullClark,
                    render::mesh::MeshLimits limits = {}) {
  try {
    formats::readObj(obj, scheme, limits);
  } catch (const InputError& error) {
    return error;
  }
  ADD_FAILURE() << "accepted OBJ:\n" << obj;
  return InputError(InputError::Kind::InvalidParameter, "", "");
}

// ---------------------------------------------------------------------------------------------
// Base64 and error bodies

TEST(Base64, MatchesRfc4648Vectors) {
  const std::pair<const char*, const char*> vectors[] = {{"", ""},
                                                         {"f", "Zg=="},
                                                         {"fo", "Zm8="},
                                                         {"foo", "Zm9v"},
                                                         {"foob", "Zm9vYg=="},
                                                         {"fooba", "Zm9vYmE="},
                                                         {"foobar", "Zm9vYmFy"}};
  for (const auto& [plain, encoded] : vectors) {
    EXPECT_EQ(api::encodeBase64(std::string_view(plain)), encoded);
    auto decoded = api::decodeBase64(encoded);
    ASSERT_TRUE(decoded.has_value()) << encoded;
    EXPECT_EQ(std::string(decoded->begin(), decoded->end()), plain);
  }
}

TEST(Base64, RoundTripsEveryByteValue) {
  std::vector<unsigned char> bytes;
  for (int i = 0; i < 256 * 3 + 1; ++i) bytes.push_back(static_cast<unsigned char>(i * 7));
  std::string text = api::encodeBase64(bytes);
  EXPECT_EQ(text.size(), (bytes.size() + 2) / 3 * 4);
  EXPECT_EQ(api::decodeBase64(text), bytes);
  EXPECT_FALSE(api::decodeBase64("Zm9").has_value());
  EXPECT_FALSE(api::decodeBase64("Zm!v").has_value());
  EXPECT_FALSE(api::decodeBase64("Z=9v").has_value());
}

TEST(ErrorAnswer, HasCodeMessageAndDetail) {
  api::Answer answer = api::errorAnswer(api::invalidRequest("camera.width", "bad \"width\""));
  EXPECT_EQ(answer.status, 400);
  EXPECT_EQ(answer.contentType, "application/json");
  rapidjson::Document doc;
  doc.Parse(answer.body.c_str());
  ASSERT_FALSE(doc.HasParseError()) << answer.body;
  EXPECT_STREQ(doc["error"]["code"].GetString(), "invalid_request");
  EXPECT_STREQ(doc["error"]["message"].GetString(), "bad \"width\"");
  EXPECT_STREQ(doc["error"]["detail"]["field"].GetString(), "camera.width");

  // A malformed detail never breaks the body.
  answer = api::errorAnswer({500, "internal", "x", "{not json"});
  doc.Parse(answer.body.c_str());
  ASSERT_FALSE(doc.HasParseError()) << answer.body;
  EXPECT_TRUE(doc["error"]["detail"].IsObject());
}

// ---------------------------------------------------------------------------------------------
// OBJ reader

TEST(ObjReader, ReadsCubeWithDefaultEdgeOnlyBoundary) {
  formats::ObjMesh obj = formats::readObj(kCubeObj, Scheme::CatmullClark, {});
  const ControlMesh& m = obj.mesh;
  EXPECT_EQ(m.vertexCount(), 8);
  EXPECT_EQ(m.faceCount(), 6);
  EXPECT_EQ(m.faceVertexIndices.size(), 24u);
  EXPECT_EQ(m.faceVertexIndices[0], 0);
  EXPECT_EQ(m.faceVertexIndices[2], 3);
  EXPECT_DOUBLE_EQ(m.points[1].x, 1.0);
  EXPECT_DOUBLE_EQ(m.points[6].z, -1.0);
  EXPECT_EQ(m.boundary, BoundaryInterpolation::EdgeOnly);
  EXPECT_TRUE(obj.warnings.empty());
  EXPECT_EQ(obj.faceLines[0], 10);  // after the comment and 8 vertices: 1-based
  EXPECT_EQ(obj.vertexLines[0], 2);
}

TEST(ObjReader, EveryCorpusFileParsesWithItsCounts) {
  if (!fs::exists(corpusDir())) GTEST_SKIP() << "no corpus at " << corpusDir();
  int files = 0;
  for (const auto& entry : fs::directory_iterator(corpusDir())) {
    if (entry.path().extension() != ".obj") continue;
    ++files;
    std::string name = entry.path().stem().string();
    std::string text = readFile(entry.path());
    // Independent counts: lines that start with "v " / "f " / "t ".
    int vertices = 0, faces = 0, creasePairs = 0;
    std::istringstream lines(text);
    for (std::string line; std::getline(lines, line);) {
      if (line.rfind("v ", 0) == 0) ++vertices;
      if (line.rfind("f ", 0) == 0) ++faces;
      if (line.rfind("t crease ", 0) == 0) creasePairs += std::atoi(line.c_str() + 9) / 2;
    }
    try {
      formats::ObjMesh obj = formats::parseObj(text, schemeOfCorpusFile(name), {});
      EXPECT_EQ(obj.mesh.vertexCount(), vertices) << name;
      EXPECT_EQ(obj.mesh.faceCount(), faces) << name;
      EXPECT_EQ(static_cast<int>(obj.mesh.creases.size()), creasePairs) << name;
      EXPECT_EQ(obj.mesh.scheme, schemeOfCorpusFile(name));
      EXPECT_TRUE(obj.warnings.empty()) << name << ": " << obj.warnings.front();
    } catch (const InputError& error) {
      ADD_FAILURE() << name << ": " << error.what();
    }
  }
  EXPECT_EQ(files, 44);
}

TEST(ObjReader, EveryCorpusFileIsAcceptedOrRefusedWithAClearError) {
  if (!fs::exists(corpusDir())) GTEST_SKIP() << "no corpus at " << corpusDir();
  // validateMesh() refuses faces that repeat a vertex on an edge, which the two non-manifold
  // shapes contain on purpose ("f 46 46 49"); OpenSubdiv itself accepts them. Either answer is
  // acceptable here as long as a refusal names the face and its OBJ line.
  for (const auto& entry : fs::directory_iterator(corpusDir())) {
    if (entry.path().extension() != ".obj") continue;
    std::string name = entry.path().stem().string();
    try {
      formats::readObj(readFile(entry.path()), schemeOfCorpusFile(name), {});
    } catch (const InputError& error) {
      EXPECT_NE(name.find("nonman"), std::string::npos) << name << ": " << error.what();
      EXPECT_EQ(error.subject().rfind("face ", 0), 0u) << name << ": " << error.what();
      EXPECT_TRUE(contains(error.what(), "OBJ line")) << name << ": " << error.what();
    }
  }
}

TEST(ObjReader, CorpusTagsHaveTheirExactValues) {
  if (!fs::exists(corpusDir())) GTEST_SKIP() << "no corpus at " << corpusDir();
  formats::ObjMesh creases = readCorpus("catmark_cube_creases0");
  ASSERT_EQ(creases.mesh.creases.size(), 2u);
  EXPECT_EQ(creases.mesh.creases[0].v0, 0);
  EXPECT_EQ(creases.mesh.creases[0].v1, 1);
  EXPECT_FLOAT_EQ(creases.mesh.creases[0].sharpness, 2.0f);
  EXPECT_EQ(creases.mesh.creases[1].v0, 1);
  EXPECT_EQ(creases.mesh.creases[1].v1, 3);
  EXPECT_EQ(creases.mesh.boundary, BoundaryInterpolation::EdgeOnly);

  formats::ObjMesh hole = readCorpus("catmark_hole_test1");
  EXPECT_EQ(hole.mesh.holes, std::vector<int>{1});
  EXPECT_EQ(hole.holeLines.size(), 1u);

  formats::ObjMesh corner = readCorpus("catmark_cube_corner0");
  ASSERT_EQ(corner.mesh.corners.size(), 1u);
  EXPECT_EQ(corner.mesh.corners[0].vertex, 0);
  EXPECT_FLOAT_EQ(corner.mesh.corners[0].sharpness, 0.7f);

  EXPECT_EQ(readCorpus("catmark_nonman_edges").mesh.boundary, BoundaryInterpolation::EdgeAndCorner);
  // Despite its name, this shape says "t creasemethod 0/0/1 normal".
  EXPECT_EQ(readCorpus("catmark_chaikin0").mesh.creaseMethod, render::mesh::CreaseMethod::Uniform);
  EXPECT_EQ(readCorpus("catmark_chaikin0").mesh.creases.size(), 28u);
  EXPECT_EQ(readCorpus("catmark_smoothtris0").mesh.triangleSubdivision,
            render::mesh::TriangleSubdivision::CatmullClark);

  formats::ObjMesh loop = readCorpus("loop_cube_creases0");
  ASSERT_EQ(loop.mesh.creases.size(), 2u);
  EXPECT_FLOAT_EQ(loop.mesh.creases[1].sharpness, 2.8f);
  EXPECT_EQ(loop.mesh.creases[1].v0, 3);
  EXPECT_EQ(loop.mesh.creases[1].v1, 2);
}

TEST(ObjReader, ReadsAllTagForms) {
  std::string obj = std::string(kCubeObj) +
                    "t crease 4/1/0 0 1 1 3 1.5\n"   // two pairs, one sharpness
                    "t crease 4/2/0 3 2 2 0 3 10\n"  // one sharpness per pair
                    "t corner 2/1/0 4 5 2.5\n"
                    "t corner 2/2/0 6 7 1 2\n"
                    "t hole 2/0/0 1 2\n"
                    "t interpolateboundary 1/0/0 0\n"
                    "t creasemethod 0/0/1 chaikin\n"
                    "t smoothtriangles 0/0/1 smooth\n";
  formats::ObjMesh out = formats::readObj(obj, Scheme::CatmullClark, {});
  const ControlMesh& m = out.mesh;
  ASSERT_EQ(m.creases.size(), 4u);
  EXPECT_FLOAT_EQ(m.creases[1].sharpness, 1.5f);
  EXPECT_EQ(m.creases[2].v0, 3);
  EXPECT_FLOAT_EQ(m.creases[2].sharpness, 3.0f);
  EXPECT_FLOAT_EQ(m.creases[3].sharpness, 10.0f);
  ASSERT_EQ(m.corners.size(), 4u);
  EXPECT_FLOAT_EQ(m.corners[1].sharpness, 2.5f);
  EXPECT_EQ(m.corners[3].vertex, 7);
  EXPECT_FLOAT_EQ(m.corners[3].sharpness, 2.0f);
  EXPECT_EQ(m.holes, (std::vector<int>{1, 2}));
  EXPECT_EQ(m.boundary, BoundaryInterpolation::None);
  EXPECT_EQ(m.creaseMethod, render::mesh::CreaseMethod::Chaikin);
  EXPECT_EQ(m.triangleSubdivision, render::mesh::TriangleSubdivision::Smooth);
  for (int boundary : {1, 2}) {
    formats::ObjMesh b = formats::readObj(
        std::string(kCubeObj) + "t interpolateboundary 1/0/0 " + std::to_string(boundary) + "\n",
        Scheme::CatmullClark, {});
    EXPECT_EQ(b.mesh.boundary, boundary == 1 ? BoundaryInterpolation::EdgeAndCorner
                                             : BoundaryInterpolation::EdgeOnly);
  }
}

TEST(ObjReader, KeepsTagsAfterATrailingGroupAndHandlesGroupsAndLineEndings) {
  // tinyobjloader alone would lose this crease: it follows a group with no faces.
  std::string obj =
      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\r\n"
      "g first\nf 1 2 3\ng second\nusemtl red\nf -4 -2 -1\r\n"
      "g trailing\rt crease 2/1/0 0 1 3.0\n";
  formats::ObjMesh out = formats::readObj(obj, Scheme::CatmullClark, {});
  EXPECT_EQ(out.mesh.faceCount(), 2);
  EXPECT_EQ(out.mesh.faceVertexIndices, (std::vector<int>{0, 1, 2, 0, 2, 3}));
  ASSERT_EQ(out.mesh.creases.size(), 1u);
  EXPECT_FLOAT_EQ(out.mesh.creases[0].sharpness, 3.0f);
  EXPECT_EQ(out.creaseLines[0], 11);  // \r\n, \n and a lone \r all end a line
}

TEST(ObjReader, IgnoresTexturesNormalsAndWarnsOnUnknownTags) {
  std::string obj =
      "v 0 0 0\nv 1 0 0\nv 1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvn 0 0 1\n"
      "s off\no thing\nmtllib x.mtl\nf 1/1/1 2/2/1 3/3/1\nl 1 2\n"
      "t facevaryingpropagatecorners 1/0/0 1\n";
  formats::ObjMesh out = formats::readObj(obj, Scheme::Loop, {});
  EXPECT_EQ(out.mesh.faceCount(), 1);
  ASSERT_EQ(out.warnings.size(), 2u);
  EXPECT_TRUE(contains(out.warnings[0], "line 12")) << out.warnings[0];
  EXPECT_TRUE(contains(out.warnings[1], "facevaryingpropagatecorners")) << out.warnings[1];
  EXPECT_TRUE(contains(out.warnings[1], "line 13")) << out.warnings[1];
}

TEST(ObjReader, FaceWithFewerThanThreeVerticesNamesItsLine) {
  // tinyobjloader would drop this face without a word.
  InputError e = objError("v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\nf 1 2\n");
  EXPECT_EQ(e.kind(), InputError::Kind::InvalidMesh);
  EXPECT_EQ(e.subject(), "line 5");
  EXPECT_TRUE(contains(e.what(), "face 1 has 2 vertices")) << e.what();
}

TEST(ObjReader, BadIndicesNameTheLine) {
  const std::string tri = "v 0 0 0\nv 1 0 0\nv 1 1 0\n";
  InputError zero = objError(tri + "f 1 2 0\n");
  EXPECT_EQ(zero.subject(), "line 4");
  EXPECT_TRUE(contains(zero.what(), "\"0\"")) << zero.what();

  InputError outside = objError(tri + "f 1 2 9\n");
  EXPECT_EQ(outside.kind(), InputError::Kind::InvalidMesh);
  EXPECT_TRUE(contains(outside.what(), "line 4")) << outside.what();
  EXPECT_TRUE(contains(outside.what(), "vertex 9")) << outside.what();
  EXPECT_TRUE(contains(outside.what(), "only 3 vertices")) << outside.what();

  InputError relative = objError(tri + "f -1 -2 -9\n");
  EXPECT_EQ(relative.subject(), "line 4");
  EXPECT_TRUE(contains(relative.what(), "-9")) << relative.what();

  InputError text = objError(tri + "f 1 2 x\n");
  EXPECT_EQ(text.subject(), "line 4");
  InputError slashes = objError(tri + "f 1/1/1/1 2 3\n");
  EXPECT_EQ(slashes.subject(), "line 4");
  // A face that repeats a vertex is non-manifold, not malformed: OpenSubdiv takes it.
  EXPECT_NO_THROW(formats::readObj(tri + "f 1 2 2\n", render::mesh::Scheme::CatmullClark, {}));
}

TEST(ObjReader, BadCoordinatesNameTheLine) {
  for (const char* bad : {"nan", "abc", "1e999", "-inf", "0x10", "1.5.3", "."}) {
    InputError e = objError(std::string("v 0 0 0\nv 1 0 ") + bad + "\nv 1 1 0\nf 1 2 3\n");
    EXPECT_EQ(e.kind(), InputError::Kind::InvalidMesh) << bad;
    EXPECT_EQ(e.subject(), "line 2") << bad << ": " << e.what();
    EXPECT_TRUE(contains(e.what(), bad)) << e.what();
  }
  EXPECT_TRUE(contains(objError("v 1 0 1e999\n").what(), "not finite"));
  EXPECT_TRUE(contains(objError("v 1 0 nan\n").what(), "not finite"));
  EXPECT_TRUE(contains(objError("v 1 0 abc\n").what(), "not a decimal number"));
  EXPECT_EQ(objError("v 1 0\n").subject(), "line 1");  // tinyobjloader would make z = 0
  // Valid forms of numbers are read as numbers.
  formats::ObjMesh ok = formats::readObj(
      "v +1.5e2 -.5 7.\nv 1 0 0 1\nv 1 1 0 0.5 0.5 0.5\nf 1 2 3\n", Scheme::Loop, {});
  EXPECT_DOUBLE_EQ(ok.mesh.points[0].x, 150.0);
  EXPECT_DOUBLE_EQ(ok.mesh.points[0].y, -0.5);
  EXPECT_DOUBLE_EQ(ok.mesh.points[0].z, 7.0);
  // Read in double precision (a float reader would keep 7 digits).
  formats::ObjMesh precise =
      formats::readObj("v 123456789.125 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n", Scheme::Loop, {});
  EXPECT_NEAR(precise.mesh.points[0].x, 123456789.125, 1e-6);  // float: off by 3
  // Finite in double but beyond what limn renders (render::mesh::kMaxCoordinate): line named.
  try {
    formats::readObj("v 1e300 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n", Scheme::Loop, {});
    ADD_FAILURE() << "1e300 was accepted";
  } catch (const render::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("line 1"), std::string::npos) << e.what();
  }
}

TEST(ObjReader, GarbageAndBadTagsNameTheLine) {
  std::string cube = kCubeObj;  // 15 lines
  EXPECT_EQ(objError(cube + "hello world\n").subject(), "line 16");
  EXPECT_EQ(objError(cube + "{\"points\": []}\n").subject(), "line 16");
  EXPECT_EQ(objError(cube + std::string("v 0 0 0\0 1\n", 11)).subject(), "line 16");
  EXPECT_EQ(objError(cube + "t crease 2/1/0 0 1\n").subject(), "line 16");        // too few
  EXPECT_EQ(objError(cube + "t crease 3/1/0 0 1 2 1.0\n").subject(), "line 16");  // odd
  EXPECT_EQ(objError(cube + "t crease 2/1/0 0 1 inf\n").subject(), "line 16");
  EXPECT_EQ(objError(cube + "t crease 2/1/0 0 x 1\n").subject(), "line 16");
  EXPECT_EQ(objError(cube + "t crease abc 0 1 1\n").subject(), "line 16");
  EXPECT_EQ(objError(cube + "t crease\n").subject(), "line 16");
  EXPECT_EQ(objError(cube + "t interpolateboundary 1/0/0 7\n").subject(), "line 16");
  EXPECT_EQ(objError(cube + "t creasemethod 0/0/1 sharp\n").subject(), "line 16");
  EXPECT_EQ(objError(cube + "t hole 1/1/0 1 2.0\n").subject(), "line 16");
}

TEST(ObjReader, SemanticErrorsNameElementAndLine) {
  std::string cube = kCubeObj;
  // 0-3 is a diagonal of face 0, not an edge.
  InputError crease = objError(cube + "t crease 2/1/0 0 1 1.0\nt crease 2/1/0 0 3 1.0\n");
  EXPECT_EQ(crease.subject(), "crease 1");
  EXPECT_TRUE(contains(crease.what(), "not an edge")) << crease.what();
  EXPECT_TRUE(contains(crease.what(), "OBJ line 17")) << crease.what();

  InputError corner = objError(cube + "t corner 1/1/0 8 1.0\n");
  EXPECT_EQ(corner.subject(), "corner 0");
  EXPECT_TRUE(contains(corner.what(), "OBJ line 16")) << corner.what();

  InputError hole = objError(cube + "t hole 1/0/0 6\n");
  EXPECT_EQ(hole.subject(), "hole 0");

  InputError negative = objError(cube + "t crease 2/1/0 0 1 -1\n");
  EXPECT_EQ(negative.subject(), "crease 0");

  InputError loop = objError(kCubeObj, Scheme::Loop);
  EXPECT_EQ(loop.subject(), "face 0");
  EXPECT_TRUE(contains(loop.what(), "loop")) << loop.what();
  EXPECT_TRUE(contains(loop.what(), "OBJ line 10")) << loop.what();

  EXPECT_EQ(objError("").subject(), "points");
  EXPECT_EQ(objError("# nothing\n\n").subject(), "points");
  EXPECT_EQ(objError("v 0 0 0\n").subject(), "faces");
}

TEST(ObjReader, LimitsAreCheckedWhileScanning) {
  render::mesh::MeshLimits small;
  small.maxVertices = 7;
  InputError vertices = objError(kCubeObj, Scheme::CatmullClark, small);
  EXPECT_EQ(vertices.kind(), InputError::Kind::LimitExceeded);
  EXPECT_EQ(vertices.subject(), "maxVertices");
  EXPECT_TRUE(contains(vertices.what(), "maxVertices")) << vertices.what();

  small = {};
  small.maxFaces = 5;
  InputError faces = objError(kCubeObj, Scheme::CatmullClark, small);
  EXPECT_EQ(faces.kind(), InputError::Kind::LimitExceeded);
  EXPECT_EQ(faces.subject(), "maxFaces");

  small = {};
  small.maxFaceSize = 3;
  InputError size = objError(kCubeObj, Scheme::CatmullClark, small);
  EXPECT_EQ(size.subject(), "maxFaceSize");

  // Face sizes above 255 would wrap in tinyobjloader's byte-sized counts.
  std::string big;
  std::string face = "f";
  for (int i = 1; i <= 300; ++i) {
    big += "v " + std::to_string(std::cos(i * 0.02)) + " " + std::to_string(std::sin(i * 0.02)) +
           " 0\n";
    face += " " + std::to_string(i);
  }
  small = {};
  small.maxFaceSize = 1000;
  InputError wide = objError(big + face + "\n", Scheme::CatmullClark, small);
  EXPECT_EQ(wide.kind(), InputError::Kind::InvalidMesh);
  EXPECT_TRUE(contains(wide.what(), "255")) << wide.what();
}

// ---------------------------------------------------------------------------------------------
// JSON mesh reader

ControlMesh readJson(const std::string& text, render::mesh::MeshLimits limits = {}) {
  rapidjson::Document doc;
  doc.Parse(text.c_str());
  EXPECT_FALSE(doc.HasParseError()) << text;
  return api::readJsonMesh(doc, "mesh", limits);
}

TEST(JsonMeshReader, CubeEqualsTheObjCube) {
  std::string tags =
      "t crease 2/1/0 0 1 2.5\nt corner 1/1/0 7 1.5\nt hole 1/0/0 2\n"
      "t interpolateboundary 1/0/0 1\nt creasemethod 0/0/1 chaikin\n";
  ControlMesh fromObj =
      formats::readObj(std::string(kCubeObj) + tags, Scheme::CatmullClark, {}).mesh;
  std::string json = kCubeJsonMesh;
  json.pop_back();
  json += R"(, "creaseIndices": [0, 1], "creaseLengths": [2], "creaseSharpnesses": [2.5],
             "cornerIndices": [7], "cornerSharpnesses": [1.5], "holeIndices": [2],
             "interpolateBoundary": "edge-and-corner", "creaseMethod": "chaikin"})";
  ControlMesh fromJson = readJson(json);

  ASSERT_EQ(fromJson.vertexCount(), fromObj.vertexCount());
  for (int v = 0; v < fromObj.vertexCount(); ++v) {
    EXPECT_EQ(fromJson.points[v].x, fromObj.points[v].x);
    EXPECT_EQ(fromJson.points[v].y, fromObj.points[v].y);
    EXPECT_EQ(fromJson.points[v].z, fromObj.points[v].z);
  }
  EXPECT_EQ(fromJson.faceVertexCounts, fromObj.faceVertexCounts);
  EXPECT_EQ(fromJson.faceVertexIndices, fromObj.faceVertexIndices);
  ASSERT_EQ(fromJson.creases.size(), 1u);
  ASSERT_EQ(fromObj.creases.size(), 1u);
  EXPECT_EQ(fromJson.creases[0].v0, fromObj.creases[0].v0);
  EXPECT_EQ(fromJson.creases[0].v1, fromObj.creases[0].v1);
  EXPECT_EQ(fromJson.creases[0].sharpness, fromObj.creases[0].sharpness);
  ASSERT_EQ(fromJson.corners.size(), 1u);
  EXPECT_EQ(fromJson.corners[0].vertex, fromObj.corners[0].vertex);
  EXPECT_EQ(fromJson.corners[0].sharpness, fromObj.corners[0].sharpness);
  EXPECT_EQ(fromJson.holes, fromObj.holes);
  EXPECT_EQ(fromJson.boundary, fromObj.boundary);
  EXPECT_EQ(fromJson.creaseMethod, fromObj.creaseMethod);
  EXPECT_EQ(fromJson.scheme, fromObj.scheme);
  EXPECT_EQ(fromJson.triangleSubdivision, fromObj.triangleSubdivision);
}

TEST(JsonMeshReader, CreaseChainsTakeOneSharpnessPerChainOrPerEdge) {
  std::string base = kCubeJsonMesh;
  base.pop_back();
  // Chain 0-1-3-2 (3 edges around face 0) and chain 4-5 (1 edge).
  ControlMesh perChain = readJson(base + R"(, "creaseIndices": [0,1,3,2, 4,5],
      "creaseLengths": [4, 2], "creaseSharpnesses": [1.0, 3.0]})");
  ASSERT_EQ(perChain.creases.size(), 4u);
  EXPECT_EQ(perChain.creases[2].v0, 3);
  EXPECT_EQ(perChain.creases[2].v1, 2);
  EXPECT_FLOAT_EQ(perChain.creases[2].sharpness, 1.0f);
  EXPECT_FLOAT_EQ(perChain.creases[3].sharpness, 3.0f);

  ControlMesh perEdge = readJson(base + R"(, "creaseIndices": [0,1,3,2, 4,5],
      "creaseLengths": [4, 2], "creaseSharpnesses": [1, 2, 10, 3]})");
  ASSERT_EQ(perEdge.creases.size(), 4u);
  EXPECT_FLOAT_EQ(perEdge.creases[1].sharpness, 2.0f);
  EXPECT_FLOAT_EQ(perEdge.creases[2].sharpness, 10.0f);

  EXPECT_EQ(readJson(kCubeJsonMesh).boundary, BoundaryInterpolation::EdgeOnly);
  std::string bilinear = kCubeJsonMesh;
  bilinear.replace(bilinear.find("catmull-clark"), 13, "bilinear");
  EXPECT_EQ(readJson(bilinear).scheme, Scheme::Bilinear);
}

TEST(JsonMeshReader, TypeErrorsNameTheField) {
  auto error = [](const std::string& text) -> ApiError {
    try {
      readJson(text);
    } catch (const ApiError& e) {
      return e;
    }
    ADD_FAILURE() << "accepted " << text;
    return {0, "", ""};
  };
  ApiError point = error(R"({"points": [[0,0,0],[1,0,0],[1,1,0],[1,1]],
      "faceVertexCounts": [3], "faceVertexIndices": [0,1,2]})");
  expectError(point, 400, "invalid_request");
  EXPECT_EQ(point.message,
            "mesh.points[3] must be an array of 3 numbers, got an array of 2 values");
  EXPECT_EQ(detailMember(point, "field"), "mesh.points[3]");

  ApiError index = error(R"({"points": [[0,0,0],[1,0,0],[1,1,0]],
      "faceVertexCounts": [3], "faceVertexIndices": [0,1,"2"]})");
  EXPECT_EQ(detailMember(index, "field"), "mesh.faceVertexIndices[2]");
  EXPECT_TRUE(contains(index.message, "got a string")) << index.message;

  ApiError missing = error(R"({"points": [[0,0,0],[1,0,0],[1,1,0]], "faceVertexCounts": [3]})");
  EXPECT_EQ(detailMember(missing, "field"), "mesh.faceVertexIndices");

  ApiError scheme = error(R"({"scheme": "doo-sabin", "points": [], "faceVertexCounts": [],
      "faceVertexIndices": []})");
  EXPECT_EQ(detailMember(scheme, "field"), "mesh.scheme");
  EXPECT_TRUE(contains(scheme.message, "\"catmull-clark\", \"loop\", \"bilinear\""))
      << scheme.message;
}

TEST(JsonMeshReader, MeshErrorsAreInvalidMesh) {
  auto error = [](const std::string& text) -> InputError {
    try {
      readJson(text);
    } catch (const InputError& e) {
      return e;
    }
    ADD_FAILURE() << "accepted " << text;
    return InputError(InputError::Kind::InvalidParameter, "", "");
  };
  std::string base = kCubeJsonMesh;
  base.pop_back();
  EXPECT_EQ(error(base + R"(, "creaseIndices": [0,1,3], "creaseLengths": [2],
      "creaseSharpnesses": [1]})")
                .subject(),
            "creaseLengths");
  EXPECT_EQ(error(base + R"(, "creaseIndices": [0], "creaseLengths": [1],
      "creaseSharpnesses": [1]})")
                .subject(),
            "crease 0");
  EXPECT_EQ(error(base + R"(, "creaseIndices": [0,1,3], "creaseLengths": [3],
      "creaseSharpnesses": [1, 2, 3]})")
                .subject(),
            "creaseSharpnesses");
  EXPECT_EQ(error(base + R"(, "cornerIndices": [0, 1], "cornerSharpnesses": [1]})").subject(),
            "cornerSharpnesses");
  EXPECT_EQ(error(R"({"points": [[0,0,0],[1,0,0],[1,1,0]], "faceVertexCounts": [3],
      "faceVertexIndices": [0,1,3]})")
                .subject(),
            "face 0");
  EXPECT_EQ(error(R"({"points": [[0,0,0],[1,0,0],[1,1,0]], "faceVertexCounts": [3, 3],
      "faceVertexIndices": [0,1,2]})")
                .subject(),
            "faceVertexIndices");
  EXPECT_EQ(error(R"({"points": [], "faceVertexCounts": [], "faceVertexIndices": []})").subject(),
            "points");
}

// ---------------------------------------------------------------------------------------------
// Request parsing

TEST(RenderRequest, MinimalRequestTakesTheDefaults) {
  api::RenderRequest r = api::parseRenderRequest(cubeRequest(""), {});
  EXPECT_EQ(r.job.method, render::pipeline::Method::Adaptive);
  EXPECT_TRUE(r.job.outputs.color);
  EXPECT_FALSE(r.job.outputs.mask || r.job.outputs.depth || r.job.outputs.normal ||
               r.job.outputs.wireframe);
  EXPECT_FALSE(r.job.reference);
  EXPECT_EQ(r.job.shading, render::Shading::Smooth);
  EXPECT_EQ(r.encoding.format, render::image::Format::Png);
  EXPECT_FALSE(r.job.camera.eye || r.job.camera.width || r.job.camera.fovYDeg);
  EXPECT_EQ(r.job.params.level, 3);
  EXPECT_EQ(r.job.params.metricSupersample, 4);
  EXPECT_EQ(r.job.mesh.faceCount(), 6);
  EXPECT_TRUE(r.warnings.empty());
}

TEST(RenderRequest, ReadsEveryField) {
  std::string body = R"({"mesh": )" + std::string(kCubeJsonMesh) + R"(,
    "camera": {"eye": [0, 0, 5], "target": [0, 0.5, 0], "up": [0, 1, 0], "fovYDeg": 40,
               "projection": "orthographic", "orthoHeight": 3.5, "width": 320, "height": 200},
    "method": "uniform", "params": {"level": 2, "dicingRate": 2.5, "metricSupersample": 2},
    "shading": "flat", "outputs": ["mask", "depth", "normal", "wireframe"], "reference": true,
    "imageFormat": "exr", "futureField": {"x": 1}})";
  api::RenderRequest r = api::parseRenderRequest(body, {});
  const render::CameraSpec& c = r.job.camera;
  EXPECT_DOUBLE_EQ(c.eye->z, 5);
  EXPECT_DOUBLE_EQ(c.target->y, 0.5);
  EXPECT_DOUBLE_EQ(c.up->y, 1);
  EXPECT_DOUBLE_EQ(*c.fovYDeg, 40);
  EXPECT_EQ(*c.projection, render::Projection::Orthographic);
  EXPECT_DOUBLE_EQ(*c.orthoHeight, 3.5);
  EXPECT_EQ(*c.width, 320);
  EXPECT_EQ(*c.height, 200);
  EXPECT_EQ(r.job.method, render::pipeline::Method::Uniform);
  EXPECT_EQ(r.job.params.level, 2);
  EXPECT_DOUBLE_EQ(r.job.params.dicingRate, 2.5);
  EXPECT_EQ(r.job.params.metricSupersample, 2);
  EXPECT_EQ(r.job.shading, render::Shading::Flat);
  EXPECT_FALSE(r.job.outputs.color);
  EXPECT_TRUE(r.job.outputs.mask && r.job.outputs.depth && r.job.outputs.normal &&
              r.job.outputs.wireframe);
  EXPECT_TRUE(r.job.reference);
  EXPECT_EQ(r.encoding.format, render::image::Format::Exr);
  // Unknown fields are accepted (forward compatible) and mentioned.
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_TRUE(contains(r.warnings[0], "futureField")) << r.warnings[0];

  for (const char* method : {"coarse", "uniform", "adaptive", "limit"}) {
    EXPECT_NO_THROW(
        api::parseRenderRequest(cubeRequest(std::string(R"(, "method": ")") + method + "\""), {}));
  }
}

TEST(RenderRequest, InvalidJsonGivesOffsetAndRapidJsonText) {
  ApiError e = parseError(R"({"mesh": {"format": "obj", "data": "v"},})");
  expectError(e, 400, "invalid_json");
  EXPECT_EQ(detailMember(e, "offset"), "40");
  EXPECT_TRUE(contains(e.message, "offset 40")) << e.message;
  EXPECT_TRUE(contains(e.message, "Missing a name")) << e.message;

  expectError(parseError(""), 400, "invalid_json");
  expectError(parseError("{} trailing"), 400, "invalid_json");
  expectError(parseError(R"({"camera": {"width": 1e999}})"), 400, "invalid_json");
  expectError(parseError("{\"mesh\": \"\xff\xfe\"}"), 400, "invalid_json");  // not UTF-8
  expectError(parseError(R"({"x": NaN})"), 400, "invalid_json");
}

TEST(RenderRequest, DeepNestingIsRefusedNotACrash) {
  std::string deep = R"({"mesh": )" + std::string(200000, '[') + std::string(200000, ']') + "}";
  ApiError e = parseError(deep);
  expectError(e, 400, "invalid_request");
  EXPECT_EQ(detailMember(e, "field"), "mesh");
}

TEST(RenderRequest, WrongTypesNameTheField) {
  struct Case {
    std::string rest, field;
  };
  const Case cases[] = {
      {R"(, "camera": {"width": "512"})", "camera.width"},
      {R"(, "camera": {"width": 512.5})", "camera.width"},
      {R"(, "camera": {"eye": [0, 0]})", "camera.eye"},
      {R"(, "camera": {"eye": [0, "1", 0]})", "camera.eye"},
      {R"(, "camera": {"up": [0, 0, 0]})", "camera.up"},
      {R"(, "camera": {"projection": "fisheye"})", "camera.projection"},
      {R"(, "camera": [])", "camera"},
      {R"(, "method": 3)", "method"},
      {R"(, "params": {"level": "3"})", "params.level"},
      {R"(, "params": {"dicingRate": true})", "params.dicingRate"},
      {R"(, "shading": "phong")", "shading"},
      {R"(, "outputs": "color")", "outputs"},
      {R"(, "outputs": ["color", 1])", "outputs[1]"},
      {R"(, "reference": "yes")", "reference"},
      {R"(, "imageFormat": "gif")", "imageFormat"},
      {R"(, "imageQuality": 101)", "imageQuality"},
      {R"(, "background": "#12")", "background"},
      {R"(, "antialias": 2)", "antialias"},
  };
  for (const Case& c : cases) {
    ApiError e = parseError(cubeRequest(c.rest));
    expectError(e, 400, "invalid_request");
    EXPECT_EQ(detailMember(e, "field"), c.field) << c.rest;
    EXPECT_TRUE(contains(e.message, c.field)) << e.message;
  }
  ApiError root = parseError("[1, 2]");
  expectError(root, 400, "invalid_request");
  ApiError noMesh = parseError(R"({"method": "coarse"})");
  EXPECT_EQ(detailMember(noMesh, "field"), "mesh");
  ApiError format = parseError(R"({"mesh": {"format": "step", "data": ""}})");
  EXPECT_EQ(detailMember(format, "field"), "mesh.format");
  ApiError data = parseError(R"({"mesh": {"format": "obj", "data": 5}})");
  EXPECT_EQ(detailMember(data, "field"), "mesh.data");
  ApiError mixed = parseError(R"({"mesh": {"format": "json", "data": "v 0 0 0"}})");
  EXPECT_EQ(detailMember(mixed, "field"), "mesh.data");
}

TEST(RenderRequest, UnknownMethodAndOutputListTheValidNames) {
  ApiError method = parseError(cubeRequest(R"(, "method": "magic")"));
  expectError(method, 400, "invalid_request");
  EXPECT_TRUE(contains(method.message,
                       R"("coarse", "uniform", "adaptive", "limit", "silhouette", "patches")"))
      << method.message;
  EXPECT_TRUE(contains(method.message, "\"magic\"")) << method.message;

  api::RenderRequest gpu = api::parseRenderRequest(
      cubeRequest(R"(, "method": "patches", "params": {"tessellator": "gpu"})"), {});
  EXPECT_EQ(gpu.job.params.tessellator, render::pipeline::PatchTessellator::Gpu);
  ApiError tessellator =
      parseError(cubeRequest(R"(, "method": "patches", "params": {"tessellator": "tpu"})"));
  expectError(tessellator, 400, "invalid_request");
  EXPECT_EQ(detailMember(tessellator, "field"), "params.tessellator");
  EXPECT_TRUE(contains(tessellator.message, R"("cpu", "gpu")")) << tessellator.message;
  ApiError patchImage =
      parseError(cubeRequest(R"(, "method": "adaptive", "outputs": ["patches"])"));
  expectError(patchImage, 400, "invalid_request");
  EXPECT_TRUE(contains(patchImage.message, "method \"patches\" only")) << patchImage.message;

  ApiError output = parseError(cubeRequest(R"(, "outputs": ["color", "albedo"])"));
  expectError(output, 400, "invalid_request");
  EXPECT_EQ(detailMember(output, "field"), "outputs[1]");
  EXPECT_TRUE(contains(output.message, R"("color", "mask", "depth", "normal", "wireframe")"))
      << output.message;
}

TEST(RenderRequest, OutOfRangeCameraAndParams) {
  JobLimits limits;
  struct Case {
    std::string rest;
    int status;
    std::string field, limit;
  };
  const Case cases[] = {
      {R"(, "camera": {"width": 0})", 400, "camera.width", ""},
      {R"(, "camera": {"height": -5})", 400, "camera.height", ""},
      {R"(, "camera": {"width": 4097})", 413, "camera.width", "maxImageSide"},
      {R"(, "camera": {"height": 100000})", 413, "camera.height", "maxImageSide"},
      {R"(, "camera": {"fovYDeg": 0})", 400, "camera.fovYDeg", ""},
      {R"(, "camera": {"fovYDeg": 180})", 400, "camera.fovYDeg", ""},
      {R"(, "camera": {"orthoHeight": 0})", 400, "camera.orthoHeight", ""},
      {R"(, "camera": {"eye": [0, 0, 0]})", 400, "camera.eye", ""},  // the cube's centre
      {R"(, "camera": {"eye": [1, 2, 3], "target": [1, 2, 3]})", 400, "camera.eye", ""},
      {R"(, "params": {"level": -1})", 400, "params.level", ""},
      {R"(, "params": {"level": 7})", 413, "params.level", "maxLevel"},
      {R"(, "params": {"isolation": 0})", 400, "params.isolation", ""},
      {R"(, "params": {"isolation": 9})", 413, "params.isolation", "maxIsolation"},
      {R"(, "params": {"dicingRate": 0})", 400, "params.dicingRate", ""},
      {R"(, "params": {"dicingRate": 0.1})", 413, "params.dicingRate", "minDicingRate"},
      {R"(, "params": {"metricSupersample": 0})", 400, "params.metricSupersample", ""},
      {R"(, "params": {"metricSupersample": 9})", 413, "params.metricSupersample",
       "maxSupersample"},
  };
  for (const Case& c : cases) {
    ApiError e = parseError(cubeRequest(c.rest), limits);
    EXPECT_EQ(e.status, c.status) << c.rest << ": " << e.message;
    EXPECT_EQ(e.code, c.status == 413 ? "too_large" : "invalid_request") << c.rest;
    EXPECT_EQ(detailMember(e, "field"), c.field) << c.rest;
    if (!c.limit.empty()) {
      EXPECT_EQ(detailMember(e, "limit"), c.limit) << c.rest;
      EXPECT_TRUE(contains(e.message, c.limit)) << e.message;
    }
  }
  // The limits come from the configuration, not constants.
  limits.maxImageSide = 100;
  EXPECT_EQ(parseError(cubeRequest(R"(, "camera": {"width": 101})"), limits).status, 413);
  EXPECT_NO_THROW(api::parseRenderRequest(cubeRequest(R"(, "camera": {"width": 100},
      "params": {"level": 6, "dicingRate": 0.25, "metricSupersample": 8})"),
                                          limits));
}

TEST(RenderRequest, BadMeshesAre422NamingTheCulprit) {
  struct Case {
    std::string body, subject, inMessage;
  };
  const std::string tri = "v 0 0 0\nv 1 0 0\nv 1 1 0\n";
  const Case cases[] = {
      {objRequest(tri + "f 1 2 4\n"), "face 0", "line 4"},
      {objRequest(tri + "f 1 2\n"), "line 4", "at least 3"},
      {objRequest(kCubeObj, "loop"), "face 0", "loop"},
      {objRequest("v nan 0 0\n" + tri + "f 2 3 4\n"), "line 1", "nan"},
      {objRequest("v 1e999 0 0\n" + tri + "f 2 3 4\n"), "line 1", "not finite"},
      {objRequest(std::string(kCubeObj) + "t crease 2/1/0 0 3 1\n"), "crease 0", "not an edge"},
      {objRequest(""), "points", "no vertices"},
      {objRequest(tri), "faces", "no faces"},
      {R"({"mesh": {"points": [[0,0,0],[1,0,0],[1,1,0]], "faceVertexCounts": [3],
           "faceVertexIndices": [0,1,7]}})",
       "face 0", "vertex 7"},
      {R"({"mesh": {"points": [[0,0,0],[1,0,0],[1,1,0]], "faceVertexCounts": [2],
           "faceVertexIndices": [0,1]}})",
       "face 0", "at least 3"},
      {R"({"mesh": {"points": [], "faceVertexCounts": [], "faceVertexIndices": []}})", "points",
       "no vertices"},
  };
  for (const Case& c : cases) {
    ApiError e = parseError(c.body);
    expectError(e, 422, "invalid_mesh");
    EXPECT_EQ(detailMember(e, "subject"), c.subject) << e.message;
    EXPECT_TRUE(contains(e.message, c.inMessage)) << e.message;
  }
}

TEST(RenderRequest, OversizedMeshesAre413NamingTheLimit) {
  JobLimits limits;
  limits.mesh.maxVertices = 7;
  ApiError v = parseError(cubeRequest(""), limits);
  expectError(v, 413, "too_large");
  EXPECT_EQ(detailMember(v, "limit"), "maxVertices");
  EXPECT_TRUE(contains(v.message, "maxVertices")) << v.message;
  ApiError vj = parseError(std::string(R"({"mesh": )") + kCubeJsonMesh + "}", limits);
  expectError(vj, 413, "too_large");
  EXPECT_EQ(detailMember(vj, "limit"), "maxVertices");

  limits = {};
  limits.mesh.maxFaces = 5;
  ApiError f = parseError(cubeRequest(""), limits);
  expectError(f, 413, "too_large");
  EXPECT_EQ(detailMember(f, "limit"), "maxFaces");
  ApiError fj = parseError(std::string(R"({"mesh": )") + kCubeJsonMesh + "}", limits);
  EXPECT_EQ(detailMember(fj, "limit"), "maxFaces");
}

TEST(RenderRequest, ObjWarningsReachTheRequest) {
  api::RenderRequest r =
      api::parseRenderRequest(objRequest(std::string(kCubeObj) + "t mystery 1/0/0 3\n"), {});
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_TRUE(contains(r.warnings[0], "mystery")) << r.warnings[0];
  EXPECT_TRUE(contains(r.warnings[0], "line 16")) << r.warnings[0];
}

// ---------------------------------------------------------------------------------------------
// Response writing

render::pipeline::RenderResult handMadeResult() {
  render::Camera camera({0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 35, render::Projection::Perspective, 2.5,
                        4, 3, 0.1, 10);
  render::ImageSet images;
  render::Image color(4, 3, 4, 0.5f);
  color.at(1, 2, 0) = 1.0f;
  images.passes[render::pass::kColor] = color;
  images.passes[render::pass::kMask] = render::Image(4, 3, 1, 1.0f);
  images.passes[render::pass::kDepth] = render::Image(4, 3, 1, 4.0f);  // not requested below
  render::ImageSet reference;
  reference.passes[render::pass::kColor] = render::Image(4, 3, 4, 0.25f);
  reference.passes[render::pass::kMask] = render::Image(4, 3, 1, 1.0f);

  render::metrics::Metrics metrics;
  metrics.silhouette = render::metrics::SilhouetteMetrics{0.31, 0.05, 0.9991, 212, 0.087, 0.012, 3};
  metrics.image =
      render::metrics::ColorMetrics{0.004, std::numeric_limits<double>::infinity(), std::nullopt};
  metrics.geometry = render::metrics::GeometryMetrics{0.0002, std::nan(""), 0.00004};

  render::pipeline::Stats stats;
  stats.controlVertices = 8;
  stats.controlFaces = 6;
  stats.triangles = 48000;
  stats.vertices = 24002;
  stats.referenceTriangles = 1u << 20;
  stats.referenceCrossCheckPx = 0.125;
  render::pipeline::Timings timings{
      0.5, 1.0,  2.0,          3.0, 4.0,
      5.0, 20.0, std::nullopt, 0.0, render::metrics::MetricsTimings{0.25, 0.5, 0.75, 1.25}};
  timings.reference = render::oracle::ReferenceStats{};
  timings.reference->sceneCached = true;
  timings.reference->newtonMs = 1.5;
  return {images, reference, metrics, stats, timings, {"engine note"}, camera, {}};
}

TEST(RenderResponse, HasTheDesignShape) {
  api::RenderRequest request;
  request.job.outputs = {
      .color = true, .mask = true, .depth = false, .normal = false, .wireframe = false};
  request.job.reference = true;
  request.warnings = {"request note"};
  std::string body = api::writeRenderResponse(handMadeResult(), request);

  rapidjson::Document doc;
  doc.Parse(body.c_str());
  ASSERT_FALSE(doc.HasParseError()) << body.substr(0, 500);

  const rapidjson::Value& images = doc["images"];
  ASSERT_TRUE(images.IsObject());
  EXPECT_EQ(images.MemberCount(), 2u);  // depth exists but was not asked for
  const rapidjson::Value& color = images["color"];
  EXPECT_STREQ(color["mime"].GetString(), "image/png");
  EXPECT_EQ(color["width"].GetInt(), 4);
  EXPECT_EQ(color["height"].GetInt(), 3);
  auto png = api::decodeBase64(color["data"].GetString());
  ASSERT_TRUE(png.has_value());
  render::Image decoded = render::image::decode(*png);
  EXPECT_EQ(decoded.width, 4);
  EXPECT_EQ(decoded.height, 3);
  EXPECT_NEAR(decoded.at(1, 2, 0), 1.0f, 1e-6);
  // Linear 0.5 is written as sRGB (docs/engine.md, "Colour is linear light").
  EXPECT_NEAR(decoded.at(0, 0, 0), render::shading::linearToSrgb(0.5f), 1.0f / 255);
  EXPECT_TRUE(images.HasMember("mask"));

  const rapidjson::Value& ref = doc["reference"]["images"];
  EXPECT_TRUE(ref.HasMember("color"));
  EXPECT_TRUE(ref.HasMember("mask"));
  // The reference's own picture (linear 0.25), not the method's: the answer's images are
  // encoded together before they are written, each found again by its image.
  render::Image refColor =
      render::image::decode(*api::decodeBase64(ref["color"]["data"].GetString()));
  EXPECT_NEAR(refColor.at(1, 2, 0), render::shading::linearToSrgb(0.25f), 1.0f / 255);

  const rapidjson::Value& m = doc["metrics"];
  EXPECT_DOUBLE_EQ(m["silhouette"]["hausdorffPx"].GetDouble(), 0.31);
  EXPECT_DOUBLE_EQ(m["silhouette"]["meanPx"].GetDouble(), 0.05);
  EXPECT_DOUBLE_EQ(m["silhouette"]["iou"].GetDouble(), 0.9991);
  EXPECT_EQ(m["silhouette"]["mismatchPx"].GetInt(), 212);
  EXPECT_DOUBLE_EQ(m["silhouette"]["outlineHausdorffPx"].GetDouble(), 0.087);
  EXPECT_DOUBLE_EQ(m["silhouette"]["outlineMeanPx"].GetDouble(), 0.012);
  EXPECT_EQ(m["silhouette"]["outlineUnresolvedLoops"].GetInt(), 3);
  EXPECT_DOUBLE_EQ(m["image"]["rmse"].GetDouble(), 0.004);
  EXPECT_TRUE(m["image"]["psnr"].IsNull());  // infinity is not JSON
  EXPECT_TRUE(m["geometry"]["meanDist"].IsNull());
  EXPECT_DOUBLE_EQ(m["geometry"]["relMaxDist"].GetDouble(), 0.00004);
  EXPECT_FALSE(m.HasMember("depth"));
  EXPECT_FALSE(m.HasMember("normal"));

  const rapidjson::Value& s = doc["stats"];
  EXPECT_EQ(s["controlVertices"].GetInt(), 8);
  EXPECT_EQ(s["controlFaces"].GetInt(), 6);
  EXPECT_EQ(s["triangles"].GetInt(), 48000);
  EXPECT_EQ(s["vertices"].GetInt(), 24002);
  EXPECT_EQ(s["patches"].GetInt(), 0);
  EXPECT_EQ(s["referenceTriangles"].GetInt(), 1 << 20);
  EXPECT_DOUBLE_EQ(s["referenceCrossCheckPx"].GetDouble(), 0.125);

  const rapidjson::Value& t = doc["timings"];
  EXPECT_DOUBLE_EQ(t["parseMs"].GetDouble(), 0.5);
  EXPECT_DOUBLE_EQ(t["surfaceMs"].GetDouble(), 1.0);
  EXPECT_DOUBLE_EQ(t["approxMs"].GetDouble(), 2.0);
  EXPECT_DOUBLE_EQ(t["rasterMs"].GetDouble(), 3.0);
  EXPECT_DOUBLE_EQ(t["referenceMs"].GetDouble(), 4.0);
  EXPECT_DOUBLE_EQ(t["metricsMs"].GetDouble(), 5.0);
  double encodeMs = t["encodeMs"].GetDouble();
  EXPECT_GE(encodeMs, 0.0);
  EXPECT_NEAR(t["totalMs"].GetDouble(), 0.5 + 20.0 + encodeMs, 1e-9);
  ASSERT_TRUE(t.HasMember("referenceStages"));
  EXPECT_TRUE(t["referenceStages"]["sceneCached"].GetBool());
  EXPECT_DOUBLE_EQ(t["referenceStages"]["newtonMs"].GetDouble(), 1.5);
  ASSERT_TRUE(t.HasMember("metricsStages"));
  EXPECT_DOUBLE_EQ(t["metricsStages"]["silhouetteMs"].GetDouble(), 0.25);
  EXPECT_DOUBLE_EQ(t["metricsStages"]["geometryMs"].GetDouble(), 1.25);

  const rapidjson::Value& w = doc["warnings"];
  ASSERT_EQ(w.Size(), 2u);
  EXPECT_STREQ(w[0].GetString(), "request note");
  EXPECT_STREQ(w[1].GetString(), "engine note");

  const rapidjson::Value& c = doc["camera"];
  EXPECT_DOUBLE_EQ(c["eye"][2].GetDouble(), 5.0);
  EXPECT_DOUBLE_EQ(c["up"][1].GetDouble(), 1.0);
  EXPECT_DOUBLE_EQ(c["fovYDeg"].GetDouble(), 35.0);
  EXPECT_STREQ(c["projection"].GetString(), "perspective");
  EXPECT_DOUBLE_EQ(c["orthoHeight"].GetDouble(), 2.5);
  EXPECT_EQ(c["width"].GetInt(), 4);
  EXPECT_EQ(c["height"].GetInt(), 3);
}

TEST(RenderResponse, OmitsReferenceWhenNotAskedAndWarnsOnMissingImages) {
  api::RenderRequest request;
  request.job.outputs = {
      .color = false, .mask = false, .depth = false, .normal = true, .wireframe = false};
  request.encoding.format = render::image::Format::Exr;
  render::pipeline::RenderResult result = handMadeResult();
  result.metrics = {};
  std::string body = api::writeRenderResponse(result, request);
  rapidjson::Document doc;
  doc.Parse(body.c_str());
  ASSERT_FALSE(doc.HasParseError());
  EXPECT_FALSE(doc.HasMember("reference"));
  EXPECT_EQ(doc["images"].MemberCount(), 0u);
  EXPECT_EQ(doc["metrics"].MemberCount(), 0u);
  ASSERT_EQ(doc["warnings"].Size(), 2u);
  EXPECT_TRUE(contains(doc["warnings"][1].GetString(), "\"normal\""));

  request.job.outputs.color = true;
  body = api::writeRenderResponse(result, request);
  doc.Parse(body.c_str());
  EXPECT_STREQ(doc["images"]["color"]["mime"].GetString(), "image/x-exr");
  render::Image exr =
      render::image::decode(*api::decodeBase64(doc["images"]["color"]["data"].GetString()));
  EXPECT_FLOAT_EQ(exr.at(0, 0, 0), 0.5f);
}

// ---------------------------------------------------------------------------------------------
// handleRender

rapidjson::Document parseBody(const api::Answer& answer) {
  rapidjson::Document doc;
  doc.Parse(answer.body.c_str());
  EXPECT_FALSE(doc.HasParseError()) << answer.body.substr(0, 300);
  return doc;
}

TEST(HandleRender, TurnsEveryFailureIntoAJsonError) {
  render::pipeline::RenderContext context;
  render::CancelToken cancel;
  JobLimits limits;

  api::Answer bad = api::handleRender("{", limits, context, cancel);
  EXPECT_EQ(bad.status, 400);
  EXPECT_STREQ(parseBody(bad)["error"]["code"].GetString(), "invalid_json");

  api::Answer mesh = api::handleRender(objRequest("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n"), limits,
                                       context, cancel);
  EXPECT_EQ(mesh.status, 422);
  EXPECT_STREQ(parseBody(mesh)["error"]["code"].GetString(), "invalid_mesh");

  render::CancelToken cancelled;
  cancelled.cancel();
  api::Answer timeout = api::handleRender(cubeRequest(""), limits, context, cancelled);
  EXPECT_EQ(timeout.status, 504);
  EXPECT_STREQ(parseBody(timeout)["error"]["code"].GetString(), "timeout");

  // A context without a rasterizer is a server bug: 500 with the reason, not a crash.
  api::Answer internal =
      api::handleRender(cubeRequest(R"(, "method": "coarse")"), limits, context, cancel);
  EXPECT_EQ(internal.status, 500);
  rapidjson::Document doc = parseBody(internal);
  EXPECT_STREQ(doc["error"]["code"].GetString(), "internal");
  EXPECT_TRUE(contains(doc["error"]["message"].GetString(), "rasterizer"));
}

// A rasteriser, or null with the reason in `why` where this machine has no EGL/OpenGL context.
std::unique_ptr<render::raster::Rasterizer> tryRasterizer(std::string& why) {
  try {
    return std::make_unique<render::raster::Rasterizer>();
  } catch (const std::exception& e) {
    why = e.what();
    return nullptr;
  }
}

TEST(HandleRender, RendersTheCubeEndToEnd) {
  std::string noContext;
  std::unique_ptr<render::raster::Rasterizer> rasterizer = tryRasterizer(noContext);
  if (!rasterizer) GTEST_SKIP() << "no EGL/OpenGL context: " << noContext;
  render::pipeline::RenderContext context{.rasterizer = rasterizer.get()};
  render::CancelToken cancel;
  api::Answer answer =
      api::handleRender(cubeRequest(R"(, "method": "uniform", "params": {"level": 2},
                     "camera": {"width": 64, "height": 48}, "outputs": ["color", "mask"])"),
                        {}, context, cancel);
  ASSERT_EQ(answer.status, 200) << answer.body;
  rapidjson::Document doc = parseBody(answer);
  EXPECT_EQ(doc["images"]["color"]["width"].GetInt(), 64);
  EXPECT_EQ(doc["images"]["mask"]["height"].GetInt(), 48);
  EXPECT_EQ(doc["stats"]["controlFaces"].GetInt(), 6);
  EXPECT_EQ(doc["stats"]["triangles"].GetInt(), 6 * 16 * 2);
  EXPECT_GT(doc["timings"]["parseMs"].GetDouble(), 0.0);
  EXPECT_EQ(doc["camera"]["width"].GetInt(), 64);
  render::Image mask =
      render::image::decode(*api::decodeBase64(doc["images"]["mask"]["data"].GetString()));
  EXPECT_GT(mask.at(32, 24), 0.5f);  // the cube covers the centre
  EXPECT_LT(mask.at(0, 0), 0.5f);    // and not the corner
}

// A compared render begins its reference beside the drawing (pipeline/run.cpp): a deadline that
// passes anywhere, in the drawing or in the reference, ends the request with the timeout answer
// (both halves stopped, nothing left running on the context), and the next request on the same
// context is answered in full. The deadlines are spread over a render of ~100 ms and more.
TEST(HandleRender, ADeadlineAnywhereInACompareEndsItCleanly) {
  std::string noContext;
  std::unique_ptr<render::raster::Rasterizer> rasterizer = tryRasterizer(noContext);
  if (!rasterizer) GTEST_SKIP() << "no EGL/OpenGL context: " << noContext;
  render::pipeline::RenderContext context{.rasterizer = rasterizer.get()};
  const std::string compared = cubeRequest(R"(, "method": "uniform", "params": {"level": 5},
      "reference": true, "camera": {"width": 512, "height": 512}, "outputs": ["color"])");
  int timedOut = 0;
  for (int ms : {1, 5, 10, 20, 40, 80, 160, 320, 640}) {
    render::CancelToken cancel(std::chrono::steady_clock::now() + std::chrono::milliseconds(ms));
    api::Answer answer = api::handleRender(compared, {}, context, cancel);
    ASSERT_TRUE(answer.status == 200 || answer.status == 504) << ms << " ms: " << answer.body;
    timedOut += answer.status == 504;
  }
  EXPECT_GT(timedOut, 0);  // 1 ms cannot hold a 512^2 comparison
  render::CancelToken none;
  api::Answer full = api::handleRender(compared, {}, context, none);
  ASSERT_EQ(full.status, 200) << full.body;
  rapidjson::Document doc = parseBody(full);
  EXPECT_LT(doc["metrics"]["silhouette"]["hausdorffPx"].GetDouble(), 1.0);
  EXPECT_TRUE(doc["reference"]["images"].HasMember("color"));
}

// ---------------------------------------------------------------------------------------------
// Configuration

TEST(Config, DefaultFileEqualsTheBuiltInDefaults) {
  api::ServiceConfig file = api::loadConfig(std::string(LIMN_SOURCE_DIR) + "/configs/default.json");
  api::ServiceConfig builtIn;
  EXPECT_EQ(file.host, builtIn.host);
  EXPECT_EQ(file.port, builtIn.port);
  EXPECT_EQ(file.workers, builtIn.workers);
  EXPECT_EQ(file.queueDepth, builtIn.queueDepth);
  EXPECT_EQ(file.ioThreads, builtIn.ioThreads);
  EXPECT_EQ(file.maxBodyBytes, builtIn.maxBodyBytes);
  EXPECT_EQ(file.maxBodyBytes, 64u << 20);
  EXPECT_EQ(file.requestTimeoutMs, builtIn.requestTimeoutMs);
  EXPECT_EQ(file.limits.mesh.maxVertices, builtIn.limits.mesh.maxVertices);
  EXPECT_EQ(file.limits.mesh.maxFaces, builtIn.limits.mesh.maxFaces);
  EXPECT_EQ(file.limits.mesh.maxFaceSize, builtIn.limits.mesh.maxFaceSize);
  EXPECT_EQ(file.limits.maxImageSide, builtIn.limits.maxImageSide);
  EXPECT_EQ(file.limits.maxSupersample, builtIn.limits.maxSupersample);
  EXPECT_EQ(file.limits.maxLevel, builtIn.limits.maxLevel);
  EXPECT_EQ(file.limits.maxIsolation, builtIn.limits.maxIsolation);
  EXPECT_EQ(file.limits.maxFrames, builtIn.limits.maxFrames);
  EXPECT_EQ(file.limits.maxFramePixels, builtIn.limits.maxFramePixels);
  EXPECT_EQ(file.limits.minDicingRate, builtIn.limits.minDicingRate);
  EXPECT_EQ(file.limits.maxTriangles, builtIn.limits.maxTriangles);
  EXPECT_EQ(file.limits.mesh.maxValence, builtIn.limits.mesh.maxValence);
  EXPECT_EQ(file.referenceCacheBytes, builtIn.referenceCacheBytes);
  EXPECT_EQ(file.meshCacheBytes, builtIn.meshCacheBytes);
  EXPECT_TRUE(file.authToken.empty());
  EXPECT_TRUE(file.corsOrigins.empty());
  EXPECT_EQ(file.logLevel, builtIn.logLevel);
  EXPECT_EQ(file.jobRetentionSeconds, builtIn.jobRetentionSeconds);
  EXPECT_TRUE(file.jobStore.empty());  // the SQLite file in the data folder
  EXPECT_EQ(file.jobLeaseSeconds, builtIn.jobLeaseSeconds);
  EXPECT_EQ(file.reservedInteractiveWorkers, builtIn.reservedInteractiveWorkers);
  EXPECT_EQ(file.heavyRequestMs, builtIn.heavyRequestMs);
  EXPECT_EQ(file.heavyQueueMs, builtIn.heavyQueueMs);
  EXPECT_EQ(file.clientQueueDepth, builtIn.clientQueueDepth);
  EXPECT_EQ(file.heavyWorkerNice, builtIn.heavyWorkerNice);
}

TEST(Config, AuthTokenAndCorsOrigins) {
  api::ServiceConfig c =
      api::parseConfig(R"({"authToken": "t0ken", "corsOrigins": ["http://localhost:5173", "*"]})");
  EXPECT_EQ(c.authToken, "t0ken");
  ASSERT_EQ(c.corsOrigins.size(), 2u);
  EXPECT_EQ(c.corsOrigins[1], "*");
  EXPECT_THROW(api::parseConfig(R"({"authToken": ""})"), api::ConfigError);
  EXPECT_THROW(api::parseConfig(R"({"corsOrigins": "*"})"), api::ConfigError);
  EXPECT_THROW(api::parseConfig(R"({"corsOrigins": [1]})"), api::ConfigError);
  EXPECT_EQ(api::parseConfig(R"({"logLevel": "warn"})").logLevel, "warn");
  EXPECT_THROW(api::parseConfig(R"({"logLevel": "loud"})"), api::ConfigError);
}

// Found by the config fuzzer: a key with an embedded NUL ("port\u0000x") once matched "port" by
// its C-string prefix and was then looked up whole, which rapidjson asserts on.
TEST(Config, KeysWithEmbeddedNulOrRepeatedAreRefusedNotLookedUpByPrefix) {
  try {
    api::parseConfig(R"({"port\u0000x": 8081})");
    FAIL() << "a key with an embedded NUL was accepted";
  } catch (const api::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("is not a known key"), std::string::npos) << e.what();
  }
  EXPECT_THROW(api::parseConfig(R"({"limits": {"maxFaces\u0000": 10}})"), api::ConfigError);
  EXPECT_THROW(api::parseConfig(R"({"port": 1, "port": 2})"), api::ConfigError);
}

TEST(Config, ReadsValuesAndKeepsDefaultsForMissingKeys) {
  api::ServiceConfig c = api::parseConfig(
      R"({"port": 0, "workers": 3, "limits": {"maxImageSide": 1024, "minDicingRate": 0.5}})");
  EXPECT_EQ(c.port, 0);
  EXPECT_EQ(c.workers, 3);
  EXPECT_EQ(c.limits.maxImageSide, 1024);
  EXPECT_DOUBLE_EQ(c.limits.minDicingRate, 0.5);
  EXPECT_EQ(c.queueDepth, 16);
  EXPECT_EQ(c.limits.mesh.maxFaces, 200000);
}

TEST(Config, ErrorsNameTheKey) {
  auto message = [](const std::string& json) -> std::string {
    try {
      api::parseConfig(json, "test.json");
    } catch (const api::ConfigError& e) {
      return e.what();
    }
    ADD_FAILURE() << "accepted " << json;
    return "";
  };
  EXPECT_TRUE(contains(message(R"({"prot": 80})"), "\"prot\" is not a known key"));
  EXPECT_TRUE(contains(message(R"({"limits": {"maxVerts": 1}})"), "\"limits.maxVerts\""));
  EXPECT_TRUE(contains(message(R"({"port": "80"})"), "\"port\""));
  EXPECT_TRUE(contains(message(R"({"port": 70000})"), "\"port\""));
  EXPECT_TRUE(contains(message(R"({"limits": {"minDicingRate": 0}})"), "limits.minDicingRate"));
  EXPECT_TRUE(contains(message(R"({"limits": []})"), "limits"));
  EXPECT_TRUE(contains(message("{"), "test.json: not valid JSON"));
  EXPECT_THROW(api::loadConfig("/nonexistent/limn.json"), api::ConfigError);
}

// ---------------------------------------------------------------------------------------------
// OpenAPI document

TEST(OpenApi, EmbeddedDocumentIsTheFileAndDescribesTheEndpoints) {
  std::string_view embedded = api::openApiDocument();
  EXPECT_EQ(embedded, readFile(fs::path(LIMN_SOURCE_DIR) / "api" / "openapi.json"));
  rapidjson::Document doc;
  doc.Parse(embedded.data(), embedded.size());
  ASSERT_FALSE(doc.HasParseError());
  EXPECT_EQ(std::string(doc["openapi"].GetString()).rfind("3.0", 0), 0u);
  for (const char* path : {"/v1/render", "/healthz", "/readyz", "/metrics", "/openapi.json"}) {
    EXPECT_TRUE(doc["paths"].HasMember(path)) << path;
  }
  const rapidjson::Value& schemas = doc["components"]["schemas"];
  for (const char* schema : {"RenderRequest", "RenderResponse", "Error"}) {
    EXPECT_TRUE(schemas.HasMember(schema)) << schema;
  }
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// What the web page sends: orbit cameras, the diff output, meshes by id

namespace {

TEST(RenderRequest, ReadsAnOrbitCamera) {
  api::RenderRequest r = api::parseRenderRequest(
      cubeRequest(
          R"(, "camera": {"orbit": {"azimuthDeg": 30, "elevationDeg": -20, "distance": 3}})"),
      {});
  ASSERT_TRUE(r.job.camera.orbit.has_value());
  EXPECT_EQ(r.job.camera.orbit->azimuthDeg, 30);
  EXPECT_EQ(r.job.camera.orbit->elevationDeg, -20);
  EXPECT_EQ(r.job.camera.orbit->distance, 3);
  EXPECT_FALSE(r.job.camera.eye.has_value());
  api::RenderRequest bare =
      api::parseRenderRequest(cubeRequest(R"(, "camera": {"orbit": {}})"), {});
  EXPECT_FALSE(bare.job.camera.orbit->distance.has_value());

  ApiError both = parseError(cubeRequest(R"(, "camera": {"orbit": {}, "eye": [0, 0, 4]})"));
  expectError(both, 400, "invalid_request");
  EXPECT_EQ(detailMember(both, "field"), "camera.orbit");
  EXPECT_EQ(detailMember(parseError(cubeRequest(R"(, "camera": {"orbit": {"elevationDeg": -91}})")),
                         "field"),
            "camera.orbit.elevationDeg");
  EXPECT_EQ(
      detailMember(parseError(cubeRequest(R"(, "camera": {"orbit": {"distance": -1}})")), "field"),
      "camera.orbit.distance");
  EXPECT_EQ(detailMember(parseError(cubeRequest(R"(, "camera": {"orbit": [0, 0]})")), "field"),
            "camera.orbit");
}

TEST(RenderRequest, DiffNeedsTheReference) {
  api::RenderRequest r = api::parseRenderRequest(
      cubeRequest(R"(, "outputs": ["color", "diff"], "reference": true)"), {});
  EXPECT_TRUE(r.job.outputs.diff);
  ApiError alone = parseError(cubeRequest(R"(, "outputs": ["diff"])"));
  expectError(alone, 400, "invalid_request");
  EXPECT_TRUE(contains(alone.message, "\"reference\": true")) << alone.message;
  expectError(
      parseError(cubeRequest(R"(, "method": "limit", "outputs": ["diff"], "reference": true)")),
      400, "invalid_request");
}

TEST(RenderRequest, MeshByIdComesFromTheCache) {
  render::mesh::MeshCache cache(1 << 20);
  api::RenderRequest inline_ = api::parseRenderRequest(cubeRequest(""), {});
  const std::string id = cache.put(inline_.job.mesh).id;
  api::RenderRequest byId =
      api::parseRenderRequest(R"({"mesh": {"id": ")" + id + R"("}})", {}, &cache);
  EXPECT_EQ(byId.job.mesh.faceVertexIndices, inline_.job.mesh.faceVertexIndices);
  EXPECT_EQ(byId.job.mesh.points.size(), 8u);

  auto error = [&](const std::string& body, render::mesh::MeshCache* meshes) -> ApiError {
    try {
      api::parseRenderRequest(body, {}, meshes);
    } catch (const ApiError& e) {
      return e;
    }
    ADD_FAILURE() << "accepted " << body;
    return {0, "", ""};
  };
  ApiError unknown = error(R"({"mesh": {"id": "feed"}})", &cache);
  expectError(unknown, 404, "unknown_mesh");
  EXPECT_EQ(detailMember(unknown, "id"), "feed");
  expectError(error(R"({"mesh": {"id": ")" + id + R"("}})", nullptr), 404, "unknown_mesh");
  ApiError extra = error(R"({"mesh": {"id": ")" + id + R"(", "format": "obj"}})", &cache);
  expectError(extra, 400, "invalid_request");
  EXPECT_EQ(detailMember(extra, "field"), "mesh.format");
  expectError(error(R"({"mesh": {"id": 7}})", &cache), 400, "invalid_request");
}

}  // namespace

namespace {

TEST(MeshExport, AcceptChoosesTheFormat) {
  using api::MeshFormat;
  EXPECT_EQ(api::chooseMeshFormat(""), MeshFormat::Glb);
  EXPECT_EQ(api::chooseMeshFormat("*/*"), MeshFormat::Glb);
  EXPECT_EQ(api::chooseMeshFormat("application/x-ply"), MeshFormat::Ply);
  EXPECT_EQ(api::chooseMeshFormat("model/ply"), MeshFormat::Ply);
  EXPECT_EQ(api::chooseMeshFormat("Text/Plain"), MeshFormat::Obj);
  EXPECT_EQ(api::chooseMeshFormat("model/gltf-binary;q=0.4, text/plain;q=0.8, */*;q=0.1"),
            MeshFormat::Obj);
  EXPECT_EQ(api::chooseMeshFormat("text/html, */*;q=0.5"), MeshFormat::Glb);
  EXPECT_FALSE(api::chooseMeshFormat("image/png").has_value());
  EXPECT_FALSE(api::chooseMeshFormat("text/plain;q=0").has_value());
}

TEST(MeshExport, ObjAndPlyCarryEveryVertexNormalAndTriangle) {
  render::tessellate::TriangleMesh mesh;
  mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}};
  mesh.normals.assign(4, {0, 0, 1});
  mesh.indices = {0, 1, 2, 2, 1, 3};
  const std::string obj = formats::writeObjMesh(mesh, {"two triangles"});
  EXPECT_EQ(obj.rfind("# two triangles\nv 0 0 0\n", 0), 0u);
  EXPECT_TRUE(contains(obj, "vn 0 0 1\n"));
  EXPECT_TRUE(contains(obj, "f 1//1 2//2 3//3\nf 3//3 2//2 4//4\n"));
  const std::string ply = formats::writePly(mesh, {"x"});
  EXPECT_TRUE(contains(ply, "comment x\nelement vertex 4\n"));
  EXPECT_TRUE(contains(ply, "element face 2\n"));
  EXPECT_EQ(ply.size() - (ply.find("end_header\n") + 11), 4u * 24 + 2u * 13);
  const std::string glb = formats::writeGlb(mesh, R"({"note":1})");
  EXPECT_EQ(glb.substr(0, 4), "glTF");
  EXPECT_EQ(glb.size() % 4, 0u);
  EXPECT_TRUE(contains(glb, R"("extras":{"note":1})"));
  EXPECT_TRUE(contains(glb, R"("min":[0,0,0],"max":[1,1,0])"));
  // No triangles: a valid file with an empty scene.
  const std::string empty = formats::writeGlb({}, "");
  EXPECT_TRUE(contains(empty, R"("scenes":[{"nodes":[]}])"));
  EXPECT_FALSE(contains(empty, "BIN"));
}

}  // namespace

// The scheduler's estimate of a request, read from its JSON alone (api/work_estimate.h).
TEST(WorkEstimate, ReadsSizesFromTheRequestAndRanksSmallBelowHeavy) {
  const std::string cube =
      R"({"format":"obj","data":"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\nf 4 3 2 1\n"})";
  auto none = [](const std::string&) { return -1; };
  api::WorkSize preview = api::estimateWork(
      "/v1/render",
      R"({"mesh":)" + cube + R"(,"camera":{"width":256,"height":256},"method":"coarse"})", none);
  EXPECT_EQ(preview.controlFaces, 2);
  EXPECT_EQ(preview.pixels, 256.0 * 256.0);
  EXPECT_EQ(preview.referencePixels, 0);
  EXPECT_EQ(preview.triangles, 4);
  EXPECT_EQ(preview.samplesCost, 2.5);  // anti-aliased by default
  EXPECT_EQ(api::estimateWork("/v1/render",
                              R"({"mesh":)" + cube + R"(,"camera":{"width":256,"height":256},)" +
                                  R"("antialias":1})",
                              none)
                .samplesCost,
            1.0);
  api::WorkSize compared = api::estimateWork(
      "/v1/render",
      R"({"mesh":)" + cube +
          R"(,"camera":{"width":2048,"height":2048},"method":"uniform","params":{"level":5},"reference":true})",
      none);
  EXPECT_EQ(compared.referencePixels, 2048.0 * 2048.0 * 16);  // metricSupersample 4 by default
  EXPECT_EQ(compared.triangles, 2 * 2 * 1024.0);              // 2 quads, 2 triangles, 4^5
  EXPECT_LT(api::referenceSeconds(preview), 0.05);
  EXPECT_GT(api::referenceSeconds(compared), 1.0);
  // An uploaded mesh's faces come from the cache's record; /v1/compare counts every row.
  api::WorkSize byId = api::estimateWork(
      "/v1/compare",
      R"({"mesh":{"id":"abc"},"cameras":[{"width":100,"height":100},{"width":100,"height":100}],)"
      R"("methods":["coarse",{"method":"uniform","params":{"level":1}}]})",
      [](const std::string& id) { return id == "abc" ? 50 : -1; });
  EXPECT_EQ(byId.controlFaces, 50);
  EXPECT_EQ(byId.pixels, 2 * 2 * 100.0 * 100.0);  // 2 rows x 2 cameras
  EXPECT_EQ(byId.referencePixels, 2 * 100.0 * 100.0 * 16);
  // Too large to read: heavy without a look; not JSON: the worker's 400, estimated small.
  api::WorkSize huge =
      api::estimateWork("/v1/render", std::string(api::kMaxReadBytes + 1, ' '), none);
  EXPECT_TRUE(huge.unread);
  EXPECT_GE(api::referenceSeconds(huge), 1.0);
  EXPECT_LT(api::referenceSeconds(api::estimateWork("/v1/render", "{nope", none)), 0.01);
}
