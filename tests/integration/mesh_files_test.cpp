// Mesh files through the real server (issue 27): a cage written by Assimp's own exporters to
// glTF/GLB, PLY (ASCII and binary), STL, FBX, COLLADA and 3DS, and to OFF by hand, renders like
// the OBJ it came from, inline (mesh.dataBase64) and uploaded as the file itself (POST
// /v1/meshes with its media type); a file of two meshes is merged or picked by name; bad files
// of every format are 422 naming the format, and the server keeps serving; a job takes such a
// file by id only.
#include <gtest/gtest.h>
#include <rapidjson/document.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <memory>
#include <sstream>
#include <string>

#include "api/base64.h"
#include "render/image/encode.h"
#include "tests/integration/http_client.h"
#include "tests/integration/server_process.h"
#include "tests/support/assimp_export.h"
#include "tests/unit/test_meshes.h"

namespace limn::testing {
namespace {

class MeshFilesServer : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { server_ = new ServerProcess(); }
  static void TearDownTestSuite() {
    EXPECT_EQ(server_->terminate(), 0);
    delete server_;
    server_ = nullptr;
  }
  static int port() { return server_->port(); }

  static std::unique_ptr<rapidjson::Document> answer(const std::string& path,
                                                     const std::string& body, int status = 200,
                                                     const Headers& headers = {}) {
    HttpResponse r = post(port(), path, body, headers);
    EXPECT_EQ(r.status, status) << path << ": " << r.body.substr(0, 400);
    auto doc = std::make_unique<rapidjson::Document>();
    doc->Parse(r.body.c_str());
    return doc;
  }

  static ServerProcess* server_;
};
ServerProcess* MeshFilesServer::server_ = nullptr;

std::string objText(const ControlMesh& mesh) {
  std::ostringstream obj;
  obj.precision(17);
  for (const Vec3& p : mesh.points) obj << "v " << p.x << " " << p.y << " " << p.z << "\\n";
  size_t at = 0;
  for (int n : mesh.faceVertexCounts) {
    obj << "f";
    for (int c = 0; c < n; ++c) obj << " " << mesh.faceVertexIndices[at++] + 1;
    obj << "\\n";
  }
  return obj.str();
}

// A render of the mask from one camera: the same request for every form of the mesh.
std::string maskRequest(const std::string& meshJson) {
  return R"({"mesh":)" + meshJson +
         R"(,"camera":{"width":192,"height":192,"eye":[2.6,1.9,3.8],"fovDeg":35},)"
         R"("method":"uniform","params":{"level":3},"outputs":["mask"]})";
}

std::string fileMesh(const std::string& format, const std::string& file,
                     const std::string& more = "") {
  return R"({"format":")" + format + R"(","dataBase64":")" + api::encodeBase64(file) + "\"" + more +
         "}";
}

render::Image maskOf(const rapidjson::Document& answer) {
  return render::image::decode(decodeBase64(answer["images"]["mask"]["data"].GetString()));
}

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

// Two masks of the same outline differ in at most a quarter of its pixels: on average the
// outlines lie within 0.25 px of each other.
void expectSameOutline(const render::Image& expected, const render::Image& got,
                       const std::string& what) {
  ASSERT_EQ(got.width, expected.width);
  int differing = 0;
  for (int y = 0; y < got.height; ++y)
    for (int x = 0; x < got.width; ++x)
      differing += (got.at(x, y) < 0.5f) != (expected.at(x, y) < 0.5f);
  const int outline = outlinePixels(expected);
  EXPECT_GT(outline, 100) << what;  // the surface is in the picture
  EXPECT_LE(differing, outline / 4)
      << what << ": " << differing << " pixels differ along an outline of " << outline;
}

struct FileCase {
  const char* assimpId;
  const char* format;
  bool polygons;
  bool zUp = false;  // 3DS files are z-up and read as they are
};

const FileCase kFiles[] = {
    {"glb2", "glb", false}, {"gltf2", "gltf", false}, {"ply", "ply", true},
    {"plyb", "ply", true},  {"stl", "stl", false},    {"stlb", "stl", false},
    {"fbxa", "fbx", true},  {"collada", "dae", true}, {"3ds", "3ds", false, true},
};

ControlMesh zUp(ControlMesh mesh) {
  for (Vec3& p : mesh.points) p = {p.x, p.z, -p.y};
  return mesh;
}

ControlMesh quadCage() { return displaced(torus(10, 6, /*creases=*/false), 0.05); }
ControlMesh triangleCage() { return icosahedron(); }

TEST_F(MeshFilesServer, EveryFormatRendersLikeTheObjItCameFrom) {
  for (const FileCase& c : kFiles) {
    const ControlMesh cage = c.polygons ? quadCage() : triangleCage();
    const std::string scheme = c.polygons ? "catmull-clark" : "loop";
    const ControlMesh asRead = c.zUp ? zUp(cage) : cage;
    auto fromObj = answer("/v1/render", maskRequest(R"({"format":"obj","scheme":")" + scheme +
                                                    R"(","data":")" + objText(asRead) + "\"}"));
    auto fromFile =
        answer("/v1/render",
               maskRequest(fileMesh(c.format, exportWithAssimp({{"cage", cage}}, c.assimpId))));
    expectSameOutline(maskOf(*fromObj), maskOf(*fromFile), c.assimpId);
    // The answer says how the file was read, and which scheme the faces chose.
    std::string warnings;
    for (const auto& w : (*fromFile)["warnings"].GetArray())
      warnings += std::string(w.GetString()) + "\n";
    EXPECT_NE(warnings.find(std::string("mesh read from ") + c.format), std::string::npos)
        << warnings;
    EXPECT_NE(warnings.find("scheme " + scheme), std::string::npos) << warnings;
  }
  // OFF, written by hand (Assimp has no OFF exporter).
  const ControlMesh cage = quadCage();
  auto fromObj =
      answer("/v1/render", maskRequest(R"({"format":"obj","data":")" + objText(cage) + "\"}"));
  std::string off = writeOff(cage);
  auto fromOff = answer("/v1/render", maskRequest(fileMesh("off", off)));
  expectSameOutline(maskOf(*fromObj), maskOf(*fromOff), "off");
}

TEST_F(MeshFilesServer, AFileUploadedAsItselfIsTheMeshItHolds) {
  const ControlMesh cage = triangleCage();
  const std::string glb = exportWithAssimp({{"cage", cage}}, "glb2");
  auto uploaded = answer("/v1/meshes", glb, 200, {{"Content-Type", "model/gltf-binary"}});
  EXPECT_EQ((*uploaded)["faces"].GetInt(), cage.faceCount());
  EXPECT_EQ((*uploaded)["vertices"].GetInt(), cage.vertexCount());
  EXPECT_STREQ((*uploaded)["scheme"].GetString(), "loop");
  const std::string id = (*uploaded)["id"].GetString();

  auto byId = answer("/v1/render", maskRequest(R"({"id":")" + id + "\"}"));
  auto inline_ = answer("/v1/render", maskRequest(fileMesh("glb", glb)));
  expectSameOutline(maskOf(*inline_), maskOf(*byId), "uploaded glb");

  // Any media type with ?format=, and the scheme from the query.
  auto asCatmark = answer("/v1/meshes?format=glb&scheme=catmull-clark", glb, 200,
                          {{"Content-Type", "application/octet-stream"}});
  EXPECT_STREQ((*asCatmark)["scheme"].GetString(), "catmull-clark");
  EXPECT_STRNE((*asCatmark)["id"].GetString(), id.c_str());

  // Binary PLY by its media type; OFF as text with ?format=.
  const ControlMesh quads = quadCage();
  auto ply = answer("/v1/meshes", exportWithAssimp({{"q", quads}}, "plyb"), 200,
                    {{"Content-Type", "model/ply"}});
  auto off =
      answer("/v1/meshes?format=off", writeOff(quads), 200, {{"Content-Type", "text/plain"}});
  EXPECT_EQ((*ply)["faces"].GetInt(), quads.faceCount());
  EXPECT_EQ((*off)["faces"].GetInt(), quads.faceCount());

  auto unknown = answer("/v1/meshes", glb, 415, {{"Content-Type", "image/png"}});
  EXPECT_STREQ((*unknown)["error"]["code"].GetString(), "unsupported_media_type");
}

TEST_F(MeshFilesServer, TwoMeshesInOneFileAreMergedOrPickedByName) {
  const ControlMesh ico = triangleCage();
  const std::string glb =
      exportWithAssimp({{"left", ico, {-1.8, 0, 0}}, {"right", ico, {1.8, 0, 0}}}, "glb2");
  auto merged = answer("/v1/meshes", glb, 200, {{"Content-Type", "model/gltf-binary"}});
  EXPECT_EQ((*merged)["faces"].GetInt(), 2 * ico.faceCount());
  auto right = answer("/v1/meshes?name=right", glb, 200, {{"Content-Type", "model/gltf-binary"}});
  EXPECT_EQ((*right)["faces"].GetInt(), ico.faceCount());
  auto none = answer("/v1/render", maskRequest(fileMesh("glb", glb, R"(,"name":"middle")")), 422);
  const std::string message = (*none)["error"]["message"].GetString();
  EXPECT_NE(message.find("\"left\""), std::string::npos) << message;
}

TEST_F(MeshFilesServer, BadFilesAre422NamingTheFormatAndTheServerKeepsServing) {
  const std::string cut = exportWithAssimp({{"ico", triangleCage()}}, "glb2").substr(0, 200);
  for (const char* format : {"glb", "gltf", "ply", "stl", "fbx", "dae", "3ds", "off"}) {
    auto bad = answer(
        "/v1/render",
        maskRequest(fileMesh(format, "not a " + std::string(format) + " file \x01\x02")), 422);
    const std::string message = (*bad)["error"]["message"].GetString();
    EXPECT_NE(message.find(std::string("the ") + format + " file"), std::string::npos) << message;
  }
  answer("/v1/render", maskRequest(fileMesh("glb", cut)), 422);
  // A few bytes that declare a billion vertices: refused, at once.
  const std::string bomb =
      "ply\nformat binary_little_endian 1.0\nelement vertex 1000000000\n"
      "property float x\nproperty float y\nproperty float z\nend_header\n";
  auto limit = answer("/v1/meshes", bomb, 413, {{"Content-Type", "model/ply"}});
  EXPECT_STREQ((*limit)["error"]["code"].GetString(), "too_large");
  answer("/v1/render", maskRequest(fileMesh("gltf", "{}", R"(,"data":"{}")")), 400);
  auto bad64 = answer("/v1/render", maskRequest(R"({"format":"glb","dataBase64":"***"})"), 400);
  EXPECT_STREQ((*bad64)["error"]["detail"]["field"].GetString(), "mesh.dataBase64");
  // Still serving.
  answer("/v1/render", maskRequest(fileMesh("off", writeOff(quadCage()))));
}

// A COLLADA file (found by fuzz/mesh_import) on which Assimp 5.2 grows without bound: the
// worker process that reads it passes its ceiling and is killed, the request gets its 500, and
// the server goes on with the next file.
TEST(MeshFilesIsolation, AFileThatExhaustsAssimpCostsOnlyItsRequest) {
  std::ifstream in(std::string(LIMN_SOURCE_DIR) +
                       "/fuzz/corpus/mesh_import/regression-collada-grows-without-bound",
                   std::ios::binary);
  std::string dae((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GT(dae.size(), 100u);
  dae.erase(0, 1);  // the fuzz input's first byte picks the format
  auto server = ServerProcess::withConfig(R"({"limits": {"maxWorkerMemoryBytes": 1073741824}})");
  HttpResponse crashed =
      post(server.port(), "/v1/meshes", dae, {{"Content-Type", "model/vnd.collada+xml"}});
  EXPECT_EQ(crashed.status, 500) << crashed.body.substr(0, 300);
  EXPECT_NE(crashed.body.find("worker_crashed"), std::string::npos) << crashed.body.substr(0, 300);
  HttpResponse next =
      post(server.port(), "/v1/meshes", writeOff(quadCage()), {{"Content-Type", "model/x-off"}});
  EXPECT_EQ(next.status, 200) << next.body.substr(0, 300);
  EXPECT_EQ(server.terminate(), 0);
}

TEST_F(MeshFilesServer, AJobTakesAFileOnlyByTheIdOfItsUpload) {
  const std::string glb = exportWithAssimp({{"ico", triangleCage()}}, "glb2");
  const std::string job = R"({"meshes":[{"mesh":)" + fileMesh("glb", glb) +
                          R"(}],"methods":["coarse"],"views":1,"size":32})";
  auto refused = answer("/v1/jobs", job, 400);
  const std::string message = (*refused)["error"]["message"].GetString();
  EXPECT_NE(message.find("POST /v1/meshes"), std::string::npos) << message;
}

}  // namespace
}  // namespace limn::testing
