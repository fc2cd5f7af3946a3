// Feature-adaptive patches (render/patches): the patch table against the limit surface, patch
// counts that grow with the features rather than 4x per level, crack-free tessellation across
// isolation levels, back-patch culling that only drops hidden patches, and the GPU path (the
// same plan diced by tessellation shaders on this machine's OpenGL: llvmpipe or a GPU).
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <numbers>
#include <tuple>
#include <unordered_map>

#include "render/patches/gpu_tessellation.h"
#include "render/patches/patch_set.h"
#include "render/patches/patch_tessellation.h"
#include "render/raster/rasterizer.h"
#include "render/subdiv/limit_surface.h"
#include "tests/support/random_views.h"
#include "tests/unit/test_meshes.h"

namespace limn::render::patches {
namespace {

using mesh::ControlMesh;

std::vector<std::pair<std::string, ControlMesh>> closedMeshes() {
  using namespace limn::testing;
  return {{"cube", cube()},
          {"sharp cube", sharpCube()},
          {"semi-sharp cube", semiSharpCube()},
          {"cube with sharp corners", cubeWithSharpCorners()},
          {"creased torus", torus(12, 8, true)},
          {"pentagonal prism", prism(5)},
          {"loop icosahedron", icosahedron()},
          {"sharp loop tetrahedron", sharpTetrahedron()}};
}

Camera viewOf(const PatchSet& set, int index, int side = 512) {
  Bounds bounds = set.controlBounds();
  auto views = limn::testing::randomViews(bounds, index + 1, 11, side);
  return resolveCamera(views[index].camera, bounds);
}

TEST(PatchSet, AgreesWithTheLimitSurface) {
  for (auto& [name, m] : closedMeshes()) {
    subdiv::LimitSurface surface(m);
    PatchSet set(m, subdiv::kApproxLevel, CancelToken());
    const double diag = surface.bounds().diagonal();
    double worst = 0;
    for (const Patch& patch : set.patches()) {
      for (Vec2 st : {Vec2{0.25, 0.25}, Vec2{0.5, 0.25}, Vec2{0.25, 0.5}}) {
        Vec3 p, ds, dt;
        set.evaluate(patch, st.x, st.y, p, ds, dt);
        Vec2 uv = set.toFaceUV(patch, st.x, st.y);
        subdiv::LimitSample exact = surface.evaluate(patch.baseFace, uv.x, uv.y);
        worst = std::max(worst, length(p - exact.position) / diag);
        EXPECT_GT(dot(normalize(cross(ds, dt)), exact.normal), 0.99) << name;
      }
    }
    // Bfr builds the same patches at the same isolation level.
    EXPECT_LT(worst, 1e-9) << name;
  }
}

// Displaced, the patches and Bfr still evaluate one surface: positions agree as undisplaced,
// and the Weingarten normals (from each side's own second derivatives) agree closely.
TEST(PatchSet, DisplacedPatchesAgreeWithTheDisplacedLimitSurface) {
  const subdiv::DisplacementSpec bumps{subdiv::DisplacementFunction::Bumps, 0.03, 5};
  for (auto& [name, m] : closedMeshes()) {
    const subdiv::LimitSurface surface(m, CancelToken(), bumps);
    const PatchSet set(m, subdiv::kApproxLevel, CancelToken(), bumps);
    const double diag = surface.bounds().diagonal();
    double worst = 0, worstNormal = 0;
    for (const Patch& patch : set.patches()) {
      for (Vec2 st : {Vec2{0.25, 0.25}, Vec2{0.5, 0.25}, Vec2{0.25, 0.5}}) {
        Vec3 p, ds, dt;
        set.evaluate(patch, st.x, st.y, p, ds, dt);
        const Vec2 uv = set.toFaceUV(patch, st.x, st.y);
        const subdiv::LimitSample exact = surface.evaluate(patch.baseFace, uv.x, uv.y);
        worst = std::max(worst, length(p - exact.position) / diag);
        worstNormal = std::max(worstNormal, length(normalize(cross(ds, dt)) - exact.normal));
      }
    }
    EXPECT_LT(worst, 1e-9) << name;
    // (Largest on the 1/64-size Gregory end caps at extraordinary vertices, whose derivatives
    // are the end cap's: 0.25% there on the pentagonal prism.)
    EXPECT_LT(worstNormal, 5e-3) << name;
    // Nothing is culled for facing away: the bumps turn normals out of the patches' cones.
    for (const Patch& patch : set.patches()) EXPECT_FALSE(patch.cullable) << name;
  }
}

// An animation frame on a kept tessellation: the same triangles, every vertex re-evaluated on
// the new points. Catmull-Clark and Loop limit surfaces move with affine maps of their control
// points, so doubling the points doubles every vertex and keeps every normal.
TEST(PatchTessellation, ReevaluatedMeshFollowsNewControlPoints) {
  for (auto& [name, m] : closedMeshes()) {
    PatchSet set(m, 4, CancelToken());
    TessellationOptions options;
    options.dicingRate = 3;
    options.cullHidden = false;
    const Camera camera = viewOf(set, 0, 256);
    PatchMesh mesh = tessellatePatches(set, camera, options, CancelToken());
    const PatchMesh original = mesh;
    ASSERT_EQ(mesh.vertexSources.size(), mesh.mesh.positions.size()) << name;
    reevaluatePatchMesh(set, mesh, CancelToken());
    for (size_t i = 0; i < mesh.mesh.positions.size(); ++i) {
      ASSERT_EQ(mesh.mesh.positions[i].x, original.mesh.positions[i].x) << name;
    }
    ControlMesh moved = m;
    for (Vec3& p : moved.points) p = p * 2.0;
    set.setControlPoints(moved.points);
    reevaluatePatchMesh(set, mesh, CancelToken());
    EXPECT_EQ(mesh.mesh.indices, original.mesh.indices) << name;
    double worst = 0, worstNormal = 0;
    for (size_t i = 0; i < mesh.mesh.positions.size(); ++i) {
      const Vec3 now(mesh.mesh.positions[i].x, mesh.mesh.positions[i].y, mesh.mesh.positions[i].z);
      const Vec3 before(original.mesh.positions[i].x, original.mesh.positions[i].y,
                        original.mesh.positions[i].z);
      worst = std::max(worst, length(now - before * 2.0));
      const Vec3 n(mesh.mesh.normals[i].x, mesh.mesh.normals[i].y, mesh.mesh.normals[i].z);
      const Vec3 n0(original.mesh.normals[i].x, original.mesh.normals[i].y,
                    original.mesh.normals[i].z);
      worstNormal = std::max(worstNormal, length(n - n0));
    }
    EXPECT_LT(worst, 1e-5 * set.controlBounds().diagonal()) << name;
    EXPECT_LT(worstNormal, 1e-5) << name;
  }
}

TEST(PatchSet, CountsGrowWithTheFeaturesNotFourfold) {
  const ControlMesh m = limn::testing::cube();
  std::vector<size_t> counts;
  for (int isolation = 1; isolation <= 6; ++isolation) {
    PatchSet set(m, isolation, CancelToken());
    counts.push_back(set.stats().patches);
    size_t irregular = 0;
    for (const auto& level : set.stats().byLevel) irregular += level[3];
    // Every cube corner is extraordinary: one Gregory end cap per face corner at the last level.
    EXPECT_EQ(irregular, 24u) << isolation;
  }
  for (size_t k = 2; k < counts.size(); ++k) {
    // Each level adds the same ring of patches around the 8 corners: linear growth.
    EXPECT_EQ(counts[k] - counts[k - 1], counts[k - 1] - counts[k - 2]) << k;
    EXPECT_LT(counts[k], 6u << (2 * (k + 1))) << k;  // uniform: 6 x 4^level faces
  }
}

TEST(PatchSet, NewControlPointsMoveThePatches) {
  ControlMesh m = limn::testing::cube();
  PatchSet set(m, 3, CancelToken());
  for (Vec3& p : m.points) p = p * 2.0;
  set.setControlPoints(m.points);
  subdiv::LimitSurface scaled(m);
  const Patch& patch = set.patches().front();
  Vec3 p, ds, dt;
  set.evaluate(patch, 0.5, 0.5, p, ds, dt);
  Vec2 uv = set.toFaceUV(patch, 0.5, 0.5);
  EXPECT_LT(length(p - scaled.position(patch.baseFace, uv.x, uv.y)), 1e-3);
  EXPECT_THROW(set.setControlPoints({}), std::invalid_argument);
}

// The back-patch cone test reads Loop patches' 12 points in Far's order (patch_tessellation.cpp):
// the patch's corners are points 4, 5 and 8, each the box spline's vertex mask of its
// neighbours (6/12 on the centre, 1/12 on each of six).
TEST(PatchSet, LoopPatchPointsAreInTheConeTestsOrder) {
  const PatchSet set(limn::testing::icosphere(2, mesh::Scheme::Loop), 2, CancelToken());
  const std::array<std::pair<Vec2, std::array<int, 7>>, 3> corners = {
      std::pair{Vec2{0, 0}, std::array{4, 0, 1, 3, 5, 7, 8}},
      std::pair{Vec2{1, 0}, std::array{5, 1, 2, 4, 6, 8, 9}},
      std::pair{Vec2{0, 1}, std::array{8, 4, 5, 7, 9, 10, 11}}};
  size_t checked = 0;
  for (const Patch& patch : set.patches()) {
    if (patch.type != OpenSubdiv::Far::PatchDescriptor::LOOP || patch.param.GetBoundary()) continue;
    const std::vector<Vec3> points = set.controlPoints(patch);
    for (const auto& [st, mask] : corners) {
      Vec3 p, ds, dt;
      set.evaluate(patch, st.x, st.y, p, ds, dt);
      Vec3 expected = points[mask[0]] * 0.5;
      for (int k = 1; k < 7; ++k) expected += points[mask[k]] / 12.0;
      ASSERT_LT(length(p - expected), 1e-12) << "patch " << patch.handle.patchIndex;
    }
    ++checked;
  }
  EXPECT_GT(checked, 20u);
}

// Every edge of the mesh is used by exactly two triangles, counted by vertex index and by
// vertex position (no duplicate vertices either).
void expectWatertight(const tessellate::TriangleMesh& mesh, const std::string& what) {
  std::map<std::pair<uint32_t, uint32_t>, int> uses;
  using Key = std::tuple<float, float, float>;
  std::map<std::pair<Key, Key>, int> usesByPosition;
  auto key = [&](uint32_t i) {
    return Key{mesh.positions[i].x, mesh.positions[i].y, mesh.positions[i].z};
  };
  for (size_t t = 0; t < mesh.triangleCount(); ++t) {
    for (int k = 0; k < 3; ++k) {
      uint32_t a = mesh.indices[3 * t + k], b = mesh.indices[3 * t + (k + 1) % 3];
      ++uses[std::minmax(a, b)];
      ++usesByPosition[std::minmax(key(a), key(b))];
    }
  }
  int bad = 0, badByPosition = 0;
  for (const auto& [edge, count] : uses) bad += count != 2;
  for (const auto& [edge, count] : usesByPosition) badByPosition += count != 2;
  EXPECT_EQ(bad, 0) << what;
  EXPECT_EQ(badByPosition, 0) << what;
}

TEST(PatchTessellation, IsWatertightAcrossLevelsAndDicingRates) {
  for (auto& [name, m] : closedMeshes()) {
    for (int isolation : {2, 4}) {
      PatchSet set(m, isolation, CancelToken());
      for (double rate : {1.5, 4.0, 40.0}) {
        TessellationOptions options;
        options.dicingRate = rate;
        options.cullHidden = false;
        Camera camera = viewOf(set, 1);
        PatchMesh out = tessellatePatches(set, camera, options, CancelToken());
        const std::string what =
            name + ", isolation " + std::to_string(isolation) + ", rate " + std::to_string(rate);
        expectWatertight(out.mesh, what);
        EXPECT_EQ(out.stats.patchesDrawn, set.stats().patches) << what;
        EXPECT_EQ(out.mesh.triangleFaces.size(), out.mesh.triangleCount());
        EXPECT_EQ(out.trianglePatch.size(), out.mesh.triangleCount());
        if (isolation == 4 && name != "sharp cube") {
          EXPECT_GT(out.stats.transitionEdges, 0u) << what;
        }
      }
    }
  }
}

// Patches whose edges want more than 64 segments are cut into domains (as deeper isolation
// would cut them); the cuts meet their neighbours without cracks and no edge is clamped.
TEST(PatchTessellation, CutsLargePatchesIntoDomainsWithoutCracks) {
  for (auto& [name, m] : closedMeshes()) {
    PatchSet set(m, 1, CancelToken());
    TessellationOptions options;
    options.dicingRate = 1.2;
    options.cullHidden = false;
    PatchMesh out = tessellatePatches(set, viewOf(set, 0, 512), options, CancelToken());
    expectWatertight(out.mesh, name);
    EXPECT_GT(out.stats.patchesSplit, 0u) << name;
    EXPECT_GT(out.stats.domains, set.stats().patches) << name;
    EXPECT_EQ(out.stats.clampedEdges, 0u) << name;
  }
}

TEST(PatchTessellation, TrianglesFaceTheWayTheirNormalsDo) {
  for (auto& [name, m] : closedMeshes()) {
    PatchSet set(m, 3, CancelToken());
    TessellationOptions options;
    options.cullHidden = false;
    PatchMesh out = tessellatePatches(set, viewOf(set, 0), options, CancelToken());
    const auto& mesh = out.mesh;
    size_t agree = 0, counted = 0;
    for (size_t t = 0; t < mesh.triangleCount(); ++t) {
      Vec3 p[3], n{0, 0, 0};
      for (int k = 0; k < 3; ++k) {
        p[k] = mesh.positions[mesh.indices[3 * t + k]].toDouble();
        n += mesh.normals[mesh.indices[3 * t + k]].toDouble();
      }
      Vec3 face = cross(p[1] - p[0], p[2] - p[0]);
      if (length(face) < 1e-14) continue;
      ++counted;
      agree += dot(face, n) > 0;
    }
    EXPECT_GT(agree, counted * 999 / 1000) << name;
  }
}

TEST(PatchTessellation, FinerDicingMakesMoreTrianglesAndTheBudgetIsHonouredOrFitted) {
  const ControlMesh m = limn::testing::torus(12, 8, true);
  PatchSet set(m, 3, CancelToken());
  Camera camera = viewOf(set, 0, 1024);
  TessellationOptions coarse, fine;
  fine.cullHidden = false;
  coarse.dicingRate = 8;
  fine.dicingRate = 1;
  size_t few = tessellatePatches(set, camera, coarse, CancelToken()).mesh.triangleCount();
  size_t many = tessellatePatches(set, camera, fine, CancelToken()).mesh.triangleCount();
  EXPECT_GT(many, few * 8);
  fine.maxTriangles = many / 2;
  EXPECT_THROW(tessellatePatches(set, camera, fine, CancelToken()), InputError);
  fine.fitToBudget = true;
  PatchMesh fitted = tessellatePatches(set, camera, fine, CancelToken());
  EXPECT_LE(fitted.mesh.triangleCount(), fine.maxTriangles);
  EXPECT_GT(fitted.mesh.triangleCount(), fine.maxTriangles / 4);
  EXPECT_GT(fitted.stats.dicingRate, 1.2);
  expectWatertight(fitted.mesh, "fitted");
}

TEST(PatchCulling, DropsOnlyPatchesOutsideTheViewOrFacingAwayEverywhere) {
  for (auto& [name, m] : closedMeshes()) {
    PatchSet set(m, 3, CancelToken());
    for (int view = 0; view < 4; ++view) {
      Camera camera = viewOf(set, view);
      size_t culled = 0;
      for (const Patch& patch : set.patches()) {
        if (outsideTheView(set, patch, camera)) {
          for (int i = 0; i <= 4; ++i) {
            for (int j = 0; j <= 4; ++j) {
              Vec3 p, ds, dt;
              set.evaluate(patch, i / 4.0, j / 4.0, p, ds, dt);
              Vec3 pixel = camera.project(p);
              bool inside = pixel.z > camera.nearPlane() && pixel.x >= 0 &&
                            pixel.x <= camera.width() && pixel.y >= 0 && pixel.y <= camera.height();
              EXPECT_FALSE(inside) << name << " view " << view;
            }
          }
          continue;
        }
        if (!facesAwayEverywhere(set, patch, camera)) continue;
        ++culled;
        for (int i = 0; i <= 4; ++i) {
          for (int j = 0; j <= (patch.triangle ? 4 - i : 4); ++j) {
            Vec3 p, ds, dt;
            set.evaluate(patch, i / 4.0, j / 4.0, p, ds, dt);
            EXPECT_GT(dot(cross(ds, dt), camera.viewVector(p)), 0) << name << " view " << view;
          }
        }
      }
      TessellationOptions options;
      PatchMesh out = tessellatePatches(set, camera, options, CancelToken());
      EXPECT_EQ(out.stats.patchesCulled, culled) << name;
      if (name == "cube" || name == "creased torus") {
        EXPECT_GT(culled, 0u) << name << view;
      }
    }
  }
}

// The GPU path needs a GL context current on the thread: a Rasterizer's, made once.
class GpuTessellation : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    rasterizer_ = new raster::Rasterizer();
    tessellator_ = new GpuPatchTessellator();
  }
  static void TearDownTestSuite() {
    delete tessellator_;
    delete rasterizer_;
  }
  static raster::Rasterizer* rasterizer_;
  static GpuPatchTessellator* tessellator_;
};
raster::Rasterizer* GpuTessellation::rasterizer_ = nullptr;
GpuPatchTessellator* GpuTessellation::tessellator_ = nullptr;

// The triangles' vertices welded within `tolerance` (the GPU path's sides evaluate shared
// vertices in their own patches, in float): an id per corner.
std::vector<int> weldedCorners(const tessellate::TriangleMesh& mesh, double tolerance) {
  struct CellHash {
    size_t operator()(const std::tuple<int64_t, int64_t, int64_t>& c) const {
      return std::get<0>(c) * 73856093u ^ std::get<1>(c) * 19349663u ^ std::get<2>(c) * 83492791u;
    }
  };
  std::unordered_map<std::tuple<int64_t, int64_t, int64_t>, std::vector<int>, CellHash> cells;
  std::vector<Vec3> representatives;
  std::vector<int> out;
  for (uint32_t index : mesh.indices) {
    const Vec3 p = mesh.positions[index].toDouble();
    const int64_t x = std::llround(p.x / tolerance), y = std::llround(p.y / tolerance),
                  z = std::llround(p.z / tolerance);
    int found = -1;
    for (int dx = -1; dx <= 1 && found < 0; ++dx) {
      for (int dy = -1; dy <= 1 && found < 0; ++dy) {
        for (int dz = -1; dz <= 1 && found < 0; ++dz) {
          auto it = cells.find({x + dx, y + dy, z + dz});
          if (it == cells.end()) continue;
          for (int id : it->second) {
            if (length(representatives[id] - p) <= tolerance) found = id;
          }
        }
      }
    }
    if (found < 0) {
      found = static_cast<int>(representatives.size());
      representatives.push_back(p);
      cells[{x, y, z}].push_back(found);
    }
    out.push_back(found);
  }
  return out;
}

// Welded by position, every edge of a closed surface's triangles is used exactly twice
// (triangles collapsed by the welding, at degenerate patch corners, left out).
void expectWatertightWhenWelded(const tessellate::TriangleMesh& mesh, double tolerance,
                                const std::string& what) {
  const std::vector<int> id = weldedCorners(mesh, tolerance);
  std::map<std::pair<int, int>, int> uses;
  for (size_t t = 0; t < mesh.triangleCount(); ++t) {
    const int a = id[3 * t], b = id[3 * t + 1], c = id[3 * t + 2];
    if (a == b || b == c || c == a) continue;
    ++uses[std::minmax(a, b)];
    ++uses[std::minmax(b, c)];
    ++uses[std::minmax(c, a)];
  }
  int bad = 0;
  for (const auto& [edge, count] : uses) bad += count != 2;
  EXPECT_EQ(bad, 0) << what;
}

// Every vertex on the limit surface at its (face, u, v), and with the limit normal (but at a
// few corners: those of an open mesh's boundary, where the CPU path's normals differ too).
void expectOnTheLimitSurface(const tessellate::TriangleMesh& mesh,
                             const subdiv::LimitSurface& surface, const std::string& what) {
  const double diag = surface.bounds().diagonal();
  double worst = 0;
  size_t normalsOff = 0;
  for (size_t c = 0; c < mesh.indices.size(); ++c) {
    const Vec2f uv = mesh.cornerUVs[c];
    const subdiv::LimitSample exact = surface.evaluate(mesh.triangleFaces[c / 3], uv.x, uv.y);
    const uint32_t v = mesh.indices[c];
    worst = std::max(worst, length(mesh.positions[v].toDouble() - exact.position) / diag);
    normalsOff += dot(mesh.normals[v].toDouble(), exact.normal) < 0.9;
  }
  EXPECT_LT(worst, 1e-5) << what;  // float evaluation
  EXPECT_LE(normalsOff, mesh.indices.size() / 1000) << what;
}

TEST_F(GpuTessellation, DicesThePlanOnTheLimitSurfaceWithoutCracks) {
  for (auto& [name, m] : closedMeshes()) {
    subdiv::LimitSurface surface(m);
    // At Bfr's isolation the patches are the limit surface; at 2 they are near it only.
    for (int isolation : {2, subdiv::kApproxLevel}) {
      PatchSet set(m, isolation, CancelToken());
      for (double rate : {1.5, 4.0, 40.0}) {
        TessellationOptions options;
        options.dicingRate = rate;
        options.cullHidden = false;
        const Camera camera = viewOf(set, 1);
        const std::string what =
            name + ", isolation " + std::to_string(isolation) + ", rate " + std::to_string(rate);
        const TessellationPlan plan = planPatchTessellation(set, camera, options, CancelToken());
        const PatchMesh gpu = tessellator_->tessellate(set, plan, CancelToken());
        const PatchMesh cpu = tessellatePatches(set, camera, options, CancelToken());
        EXPECT_EQ(gpu.stats.domains, cpu.stats.domains) << what;
        EXPECT_EQ(gpu.trianglePatch.size(), gpu.mesh.triangleCount()) << what;
        // The hardware pattern differs from the CPU's grid, not by much.
        EXPECT_GT(gpu.mesh.triangleCount(), cpu.mesh.triangleCount() / 2) << what;
        EXPECT_LT(gpu.mesh.triangleCount(), cpu.mesh.triangleCount() * 2) << what;
        if (isolation == subdiv::kApproxLevel) {
          expectOnTheLimitSurface(gpu.mesh, surface, what);
        }
        expectWatertightWhenWelded(gpu.mesh, 1e-5 * set.controlBounds().diagonal(), what);
      }
    }
  }
}

TEST_F(GpuTessellation, KeepsTheWindingAndCutDomainsAndBatches) {
  for (auto& [name, m] : closedMeshes()) {
    PatchSet set(m, 1, CancelToken());
    TessellationOptions options;
    options.dicingRate = 1.2;  // cuts patches into domains
    options.cullHidden = false;
    const TessellationPlan plan =
        planPatchTessellation(set, viewOf(set, 0, 512), options, CancelToken());
    ASSERT_GT(plan.stats.patchesSplit, 0u) << name;
    GpuTessellationStats stats;
    const PatchMesh gpu = tessellator_->tessellate(set, plan, CancelToken(), &stats);
    expectWatertightWhenWelded(gpu.mesh, 1e-5 * set.controlBounds().diagonal(), name);
    size_t agree = 0, counted = 0;
    for (size_t t = 0; t < gpu.mesh.triangleCount(); ++t) {
      Vec3 p[3], n{0, 0, 0};
      for (int k = 0; k < 3; ++k) {
        p[k] = gpu.mesh.positions[3 * t + k].toDouble();
        n += gpu.mesh.normals[3 * t + k].toDouble();
      }
      const Vec3 face = cross(p[1] - p[0], p[2] - p[0]);
      if (length(face) < 1e-12) continue;
      ++counted;
      agree += dot(face, n) > 0;
    }
    EXPECT_GT(agree, counted * 999 / 1000) << name;

    // Small batches: more draws, the same triangles in the same order (one mesh per scheme).
    if (name != "cube" && name != "loop icosahedron") continue;
    GpuPatchTessellator small(7);
    GpuTessellationStats smallStats;
    const PatchMesh batched = small.tessellate(set, plan, CancelToken(), &smallStats);
    EXPECT_GT(smallStats.draws, stats.draws) << name;
    ASSERT_EQ(batched.mesh.positions.size(), gpu.mesh.positions.size()) << name;
    EXPECT_TRUE(std::equal(
        batched.mesh.positions.begin(), batched.mesh.positions.end(), gpu.mesh.positions.begin(),
        [](const Vec3f& a, const Vec3f& b) { return a.x == b.x && a.y == b.y && a.z == b.z; }))
        << name;
  }
}

TEST_F(GpuTessellation, EvaluatesBoundaryPatchesOfOpenMeshes) {
  // A wavy quad grid and an icosahedron with two faces cut out (Loop, with a boundary).
  ControlMesh openIcosahedron = limn::testing::icosahedron();
  for (int k = 0; k < 2; ++k) {
    openIcosahedron.faceVertexCounts.pop_back();
    openIcosahedron.faceVertexIndices.resize(openIcosahedron.faceVertexIndices.size() - 3);
  }
  for (const ControlMesh& m : {limn::testing::grid(5), openIcosahedron}) {
    subdiv::LimitSurface surface(m);
    PatchSet set(m, subdiv::kApproxLevel, CancelToken());
    TessellationOptions options;
    options.dicingRate = 3;
    const TessellationPlan plan =
        planPatchTessellation(set, viewOf(set, 2), options, CancelToken());
    const PatchMesh gpu = tessellator_->tessellate(set, plan, CancelToken());
    ASSERT_GT(gpu.mesh.triangleCount(), 0u);
    expectOnTheLimitSurface(gpu.mesh, surface,
                            m.scheme == mesh::Scheme::Loop ? "open icosahedron" : "grid");
  }
}

TEST_F(GpuTessellation, StopsWhenCancelled) {
  const ControlMesh m = limn::testing::torus(12, 8, true);
  PatchSet set(m, 3, CancelToken());
  const TessellationPlan plan =
      planPatchTessellation(set, viewOf(set, 0), TessellationOptions{}, CancelToken());
  CancelToken cancelled;
  cancelled.cancel();
  EXPECT_THROW(tessellator_->tessellate(set, plan, cancelled), Cancelled);
}

}  // namespace
}  // namespace limn::render::patches
