// Mesh files in through Assimp (formats/assimp_import.h): every format round-trips a cage that
// Assimp's own exporters wrote (polygons kept, seams welded, node transforms applied, meshes
// merged or picked), the scheme follows the faces, and hostile files are refused with the
// format named — the ones that declare more than they hold before anything is allocated.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "formats/assimp_import.h"
#include "render/core/error.h"
#include "tests/support/assimp_export.h"
#include "tests/unit/test_meshes.h"

namespace limn::testing {
namespace {

using formats::ImportFormat;
using render::InputError;

// The cages match when each vertex of `got` lies on one of `expected` (within what a file's
// decimal or float coordinates round away: 1e-5 of the size) and the faces, as rings of those
// vertices, are the same rings in any order and vertex numbering.
void expectSameCage(const ControlMesh& expected, const ControlMesh& got, const std::string& what) {
  ASSERT_EQ(got.vertexCount(), expected.vertexCount()) << what;
  ASSERT_EQ(got.faceCount(), expected.faceCount()) << what;
  const double tolerance = 1e-5 * expected.bounds().diagonal();
  std::vector<int> original(got.points.size(), -1);
  for (size_t v = 0; v < got.points.size(); ++v) {
    for (size_t w = 0; w < expected.points.size(); ++w) {
      if (length(got.points[v] - expected.points[w]) <= tolerance)
        original[v] = static_cast<int>(w);
    }
    ASSERT_GE(original[v], 0) << what << ": vertex " << v << " is none of the cage's";
  }
  auto rings = [](const ControlMesh& mesh, const std::vector<int>* rename) {
    std::vector<std::vector<int>> faces;
    size_t at = 0;
    for (int n : mesh.faceVertexCounts) {
      std::vector<int> ring;
      for (int c = 0; c < n; ++c) {
        const int v = mesh.faceVertexIndices[at++];
        ring.push_back(rename ? (*rename)[v] : v);
      }
      std::rotate(ring.begin(), std::min_element(ring.begin(), ring.end()), ring.end());
      faces.push_back(std::move(ring));
    }
    std::sort(faces.begin(), faces.end());
    return faces;
  };
  const auto a = rings(expected, nullptr), b = rings(got, &original);
  int differing = 0;
  for (size_t i = 0; i < a.size(); ++i) differing += a[i] != b[i];
  EXPECT_EQ(differing, 0) << what << ": faces that are not the cage's, of " << a.size();
}

formats::ImportedMesh import(const std::string& bytes, ImportFormat format,
                             formats::ImportOptions options = {},
                             const render::mesh::MeshLimits& limits = {}) {
  return formats::importMesh(bytes, format, options, limits);
}

ControlMesh quadTorus() { return torus(10, 6, /*creases=*/false); }

// A pentagonal prism: five quads and two pentagons: polygons must stay polygons.
ControlMesh mixedCage() {
  ControlMesh m = prism(5);
  m.creases.clear();
  m.corners.clear();
  return m;
}

struct FormatCase {
  const char* assimpId;
  ImportFormat format;
  bool polygons;     // the format keeps faces of more than 3 corners
  bool zUp = false;  // 3DS: Assimp writes z up and reads the file's axes as they are
};

// The cage as a z-up file read back holds it: (x, y, z) -> (x, z, -y).
ControlMesh asReadFromZUp(ControlMesh mesh) {
  for (Vec3& p : mesh.points) p = {p.x, p.z, -p.y};
  return mesh;
}

const FormatCase kFormats[] = {
    {"glb2", ImportFormat::Glb, false},
    {"gltf2", ImportFormat::Gltf, false},
    {"ply", ImportFormat::Ply, true},
    {"plyb", ImportFormat::Ply, true},
    {"stl", ImportFormat::Stl, false},
    {"stlb", ImportFormat::Stl, false},
    {"fbxa", ImportFormat::Fbx, true},
    {"collada", ImportFormat::Dae, true},
    {"3ds", ImportFormat::ThreeDs, false, true},
};

TEST(AssimpImport, EveryFormatRoundTripsTheCageItWasWrittenFrom) {
  for (const FormatCase& c : kFormats) {
    // Formats of triangles only get a triangle cage; the others a cage of quads and pentagons.
    // (Assimp 5.2 cannot read its own binary FBX export, "block offset is out of range", so
    // FBX is written as ASCII: the importer is the same.)
    const std::vector<ControlMesh> cages = c.polygons
                                               ? std::vector<ControlMesh>{quadTorus(), mixedCage()}
                                               : std::vector<ControlMesh>{icosahedron()};
    for (const ControlMesh& cage : cages) {
      const std::string file = exportWithAssimp({{"cage", cage}}, c.assimpId);
      formats::ImportedMesh got = import(file, c.format);
      expectSameCage(c.zUp ? asReadFromZUp(cage) : cage, got.mesh, c.assimpId);
      EXPECT_TRUE(got.schemeChosen);
      EXPECT_EQ(got.mesh.scheme, c.polygons ? Scheme::CatmullClark : Scheme::Loop) << c.assimpId;
      EXPECT_NO_THROW(render::mesh::validateMesh(got.mesh, {})) << c.assimpId;
    }
  }
}

TEST(AssimpImport, OffFilesRoundTripWithTheirPolygons) {
  for (const ControlMesh& cage : {quadTorus(), mixedCage(), icosahedron()}) {
    formats::ImportedMesh got = import(writeOff(cage), ImportFormat::Off);
    expectSameCage(cage, got.mesh, "off");
  }
}

// glTF stores a vertex per (position, normal, UV): a flat-shaded or UV-seamed export repeats
// each corner per face, as a non-indexed glTF (written here by hand: Assimp's exporter joins
// them) and every STL do. Unwelded, the surface would fall apart into separate faces.
TEST(AssimpImport, CornersSplitPerFaceAreWeldedIntoOneSurface) {
  const ControlMesh ico = icosahedron();
  const int repeated = static_cast<int>(ico.faceVertexIndices.size()) - ico.vertexCount();
  formats::ImportedMesh gltf = import(nonIndexedGltf(ico), ImportFormat::Gltf);
  expectSameCage(ico, gltf.mesh, "non-indexed gltf");
  EXPECT_EQ(gltf.verticesWelded, repeated);
  for (const char* id : {"stl", "stlb"}) {
    formats::ImportedMesh stl =
        import(exportWithAssimp({{"split", ico, {0, 0, 0}, true}}, id), ImportFormat::Stl);
    expectSameCage(ico, stl.mesh, id);
  }
  for (const char* id : {"ply", "collada"}) {
    const ImportFormat format = std::string(id) == "ply" ? ImportFormat::Ply : ImportFormat::Dae;
    formats::ImportedMesh split =
        import(exportWithAssimp({{"split", quadTorus(), {0, 0, 0}, true}}, id), format);
    expectSameCage(quadTorus(), split.mesh, id);
  }
}

TEST(AssimpImport, TwoMeshesAreMergedWithTheirTransformsOrPickedByName) {
  // glTF holds triangles: two icosahedra, three units either side of the origin.
  ControlMesh ico = icosahedron();
  const std::string two =
      exportWithAssimp({{"left", ico, {-3, 0, 0}}, {"right", ico, {3, 0.5, 0}}}, "glb2");
  formats::ImportedMesh merged = import(two, ImportFormat::Glb);
  EXPECT_EQ(merged.meshesMerged, 2);
  EXPECT_EQ(merged.mesh.faceCount(), 2 * ico.faceCount());
  EXPECT_EQ(merged.mesh.vertexCount(), 2 * ico.vertexCount());  // apart: nothing welds across
  const double t = (1 + std::sqrt(5.0)) / 2;                    // the icosahedron's half-width
  const render::Bounds both = merged.mesh.bounds();
  EXPECT_NEAR(both.lo.x, -3 - t, 1e-5);
  EXPECT_NEAR(both.hi.x, 3 + t, 1e-5);

  formats::ImportOptions pick;
  pick.meshName = "right";
  formats::ImportedMesh right = import(two, ImportFormat::Glb, pick);
  EXPECT_EQ(right.meshesMerged, 1);
  EXPECT_EQ(right.mesh.faceCount(), ico.faceCount());
  EXPECT_NEAR(right.mesh.bounds().lo.x, 3 - t, 1e-5);
  EXPECT_NEAR(right.mesh.bounds().hi.y, 0.5 + t, 1e-5);

  pick.meshName = "middle";
  try {
    import(two, ImportFormat::Glb, pick);
    FAIL() << "an unknown mesh name was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.subject(), "mesh.name");
    EXPECT_NE(std::string(e.what()).find("\"right\""), std::string::npos) << e.what();
  }
}

TEST(AssimpImport, TheCallersSchemeWinsOverTheFaces) {
  formats::ImportOptions options;
  options.scheme = Scheme::CatmullClark;
  formats::ImportedMesh got =
      import(exportWithAssimp({{"ico", icosahedron()}}, "glb2"), ImportFormat::Glb, options);
  EXPECT_EQ(got.mesh.scheme, Scheme::CatmullClark);
  EXPECT_FALSE(got.schemeChosen);
}

std::string expectRefused(const std::string& bytes, ImportFormat format,
                          InputError::Kind kind = InputError::Kind::InvalidMesh,
                          const render::mesh::MeshLimits& limits = {}) {
  try {
    import(bytes, format, {}, limits);
  } catch (const InputError& e) {
    EXPECT_EQ(static_cast<int>(e.kind()), static_cast<int>(kind)) << e.what();
    return e.what();
  }
  ADD_FAILURE() << formats::importFormatName(format) << ": accepted";
  return {};
}

TEST(AssimpImport, BadFilesOfEveryFormatAreRefusedNamingTheFormat) {
  const std::string garbage = "this is not a mesh file at all \x01\x02\x03";
  for (const std::string& name : formats::importFormatNames()) {
    const ImportFormat format = *formats::importFormatNamed(name);
    const std::string message = expectRefused(garbage, format);
    EXPECT_NE(message.find(name), std::string::npos) << message;
    expectRefused("", format);
  }
  // Real files cut short, in their header and in their data.
  for (const FormatCase& c : kFormats) {
    const std::string file = exportWithAssimp({{"ico", icosahedron()}}, c.assimpId);
    for (size_t keep : {file.size() / 8, file.size() / 3, file.size() * 2 / 3}) {
      SCOPED_TRACE(std::string(c.assimpId) + " cut to " + std::to_string(keep) + " bytes");
      expectRefused(file.substr(0, keep), c.format);
    }
  }
}

// A few hundred bytes that declare millions of elements: refused by the counts, before Assimp
// reserves memory for them (with limits high enough that only the file's honesty is at stake).
TEST(AssimpImport, FilesDeclaringMoreThanTheyHoldAreRefusedBeforeAllocating) {
  render::mesh::MeshLimits generous;
  generous.maxVertices = generous.maxFaces = 2'000'000'000;
  const std::string ply =
      "ply\nformat binary_little_endian 1.0\nelement vertex 1500000000\nproperty float x\n"
      "property float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\n"
      "end_header\n" +
      std::string(64, '\0');
  EXPECT_NE(expectRefused(ply, ImportFormat::Ply, InputError::Kind::InvalidMesh, generous)
                .find("1500000000 vertices"),
            std::string::npos);
  EXPECT_NE(expectRefused(ply, ImportFormat::Ply, InputError::Kind::LimitExceeded).find("vertices"),
            std::string::npos);

  expectRefused("OFF\n900000000 900000000 0\n0 0 0\n", ImportFormat::Off,
                InputError::Kind::InvalidMesh, generous);

  std::string stl(84, '\0');
  const uint32_t triangles = 400'000'000;
  std::memcpy(stl.data() + 80, &triangles, 4);
  EXPECT_NE(expectRefused(stl, ImportFormat::Stl, InputError::Kind::InvalidMesh, generous)
                .find("400000000 triangles"),
            std::string::npos);

  const std::string gltf =
      R"({"asset":{"version":"2.0"},"buffers":[{"byteLength":12,"uri":"data:application/octet-stream;base64,AAAAAAAAAAAAAAAA"}],)"
      R"("bufferViews":[{"buffer":0,"byteLength":12}],)"
      R"("accessors":[{"bufferView":0,"componentType":5126,"count":900000000,"type":"VEC3"}],)"
      R"("meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],"nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}]})";
  EXPECT_NE(expectRefused(gltf, ImportFormat::Gltf).find("accessor 0"), std::string::npos);

  const std::string dae = R"(<?xml version="1.0"?><COLLADA><float_array count="999999999">0 0 0)"
                          R"(</float_array></COLLADA>)";
  expectRefused(dae, ImportFormat::Dae);
}

// The file is read from memory alone: a glTF that names a file of the server's (here one that
// exists, this test's own source) as its buffer gets nothing from it.
TEST(AssimpImport, AGltfNamingAnotherFileReadsNothingFromIt) {
  const std::string path = std::string(LIMN_SOURCE_DIR) + "/tests/unit/formats_test.cpp";
  const std::string gltf =
      R"({"asset":{"version":"2.0"},"buffers":[{"byteLength":36,"uri":")" + path +
      R"("}],)"
      R"("bufferViews":[{"buffer":0,"byteLength":36}],)"
      R"("accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"}],)"
      R"("meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],"nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}]})";
  expectRefused(gltf, ImportFormat::Gltf);
}

TEST(AssimpImport, OverTheMeshLimitsIsALimitNotACrash) {
  render::mesh::MeshLimits small;
  small.maxFaces = 10;
  expectRefused(exportWithAssimp({{"ico", icosahedron()}}, "glb2"), ImportFormat::Glb,
                InputError::Kind::LimitExceeded, small);
  small = {};
  small.maxVertices = 5;
  expectRefused(writeOff(quadTorus()), ImportFormat::Off, InputError::Kind::LimitExceeded, small);
  small = {};
  small.maxFaceSize = 4;
  expectRefused(writeOff(mixedCage()), ImportFormat::Off, InputError::Kind::LimitExceeded, small);
}

TEST(AssimpImport, FormatsAreNamedAndKnownByMediaType) {
  EXPECT_EQ(formats::importFormatNamed("collada"), ImportFormat::Dae);
  EXPECT_FALSE(formats::importFormatNamed("obj").has_value());  // limn's own reader
  EXPECT_EQ(formats::importFormatOfMediaType("model/gltf-binary"), ImportFormat::Glb);
  EXPECT_EQ(formats::importFormatOfMediaType("application/x-ply"), ImportFormat::Ply);
  EXPECT_FALSE(formats::importFormatOfMediaType("application/octet-stream").has_value());
  for (const std::string& name : formats::importFormatNames()) {
    EXPECT_EQ(formats::importFormatName(*formats::importFormatNamed(name)), name);
  }
}

}  // namespace
}  // namespace limn::testing
