// uniform_bench: the `uniform` method from the cage to the mesh the rasteriser takes, per level
// and engine, with OpenSubdiv's Far timed in the same run as the baseline. Prints a Markdown
// table (bench/uniform_results.md keeps the last run).
//
// What is timed (each the minimum of --repeat runs; one run above a million output vertices):
//   Far positions   Far::TopologyRefinerFactory::Create + RefineUniform(level) +
//                   PrimvarRefiner::Interpolate at every level: positions only, the least any
//                   engine must do (no limit, no normals, no mesh);
//   opensubdiv      tessellateUniform with the OpenSubdiv engine (Far refinement, limit masks,
//                   mesh): what `"engine": "opensubdiv"` costs a request;
//   masks           tessellateUniform with limn's own rules: its levels after the first few run
//                   on halfedges (quads, or Loop's triangles), in parallel
//                   (render/rules/halfedge_level.h); refine, limit and mesh are its stages. "1
//                   thread" is the same on one thread, and "same" says whether the two meshes are
//                   identical bit for bit.
// Mvert/s: output vertices per second of the masks engine, refinement + limit + mesh.
// vs 4x prev: the masks time over 4 times the previous level's (1.0: exactly linear).
//
//   uniform_bench [--repeat N] [--max-level L] [--only TEXT]   (TEXT: part of the meshes' names)
#include <opensubdiv/far/primvarRefiner.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "formats/obj_reader.h"
#include "render/core/parallel.h"
#include "render/subdiv/far_point.h"
#include "render/subdiv/limit_surface.h"
#include "render/tessellate/tessellate.h"
#include "tests/unit/test_meshes.h"

namespace Far = OpenSubdiv::Far;
using namespace limn;
using render::mesh::ControlMesh;
using render::tessellate::TriangleMesh;
using render::tessellate::UniformEngine;
using render::tessellate::UniformOptions;

namespace {

struct NamedMesh {
  std::string name;
  ControlMesh mesh;
};

ControlMesh example(const std::string& file, render::mesh::Scheme scheme) {
  std::ifstream in(std::string(LIMN_SOURCE_DIR) + "/examples/" + file);
  std::ostringstream text;
  text << in.rdbuf();
  return formats::readObj(text.str(), scheme, {}).mesh;
}

std::vector<NamedMesh> meshes() {
  using render::mesh::Scheme;
  ControlMesh lowPoly = testing::creature(8);
  return {
      {"pawn.obj (144 faces, semi-sharp)", example("pawn.obj", Scheme::CatmullClark)},
      {"torus_creased.obj", example("torus_creased.obj", Scheme::CatmullClark)},
      {"creature(8) (" + std::to_string(lowPoly.faceCount()) + " faces)", lowPoly},
      {"creature(16) (" + std::to_string(testing::creature(16).faceCount()) + " faces)",
       testing::creature(16)},
      {"creature(32) (" + std::to_string(testing::creature(32).faceCount()) + " faces)",
       testing::creature(32)},
      {"creature(56) (" + std::to_string(testing::creature(56).faceCount()) + " faces)",
       testing::creature(56)},
      {"icosahedron.obj (Loop)", example("icosahedron.obj", Scheme::Loop)},
      {"loopCreature(16) (Loop, " + std::to_string(testing::loopCreature(16).faceCount()) +
           " faces)",
       testing::loopCreature(16)},
      {"loopCreature(32) (Loop, " + std::to_string(testing::loopCreature(32).faceCount()) +
           " faces)",
       testing::loopCreature(32)},
  };
}

double msSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

double minMs(int repeat, const std::function<void()>& work) {
  double best = 1e300;
  for (int r = 0; r < repeat; ++r) {
    const auto start = std::chrono::steady_clock::now();
    work();
    best = std::min(best, msSince(start));
  }
  return best;
}

void farPositions(const ControlMesh& m, int level) {
  auto refiner = render::subdiv::createTopologyRefiner(m);
  Far::TopologyRefiner::UniformOptions options(level);
  refiner->RefineUniform(options);
  std::vector<render::subdiv::FarPoint> points(refiner->GetNumVerticesTotal());
  for (int v = 0; v < m.vertexCount(); ++v) points[v].p = m.points[v];
  Far::PrimvarRefiner primvar(*refiner);
  render::subdiv::FarPoint* src = points.data();
  for (int l = 1; l <= level; ++l) {
    render::subdiv::FarPoint* dst = src + refiner->GetLevel(l - 1).GetNumVertices();
    primvar.Interpolate(l, src, dst);
    src = dst;
  }
}

struct Run {
  double ms = 1e300;
  UniformOptions::Stages stages;  // of the fastest run
  TriangleMesh mesh;
};

Run tessellate(const render::subdiv::LimitSurface& surface, UniformOptions options, int repeat) {
  Run best;
  for (int r = 0; r < repeat; ++r) {
    UniformOptions::Stages stages;
    options.stages = &stages;
    const auto start = std::chrono::steady_clock::now();
    TriangleMesh mesh = render::tessellate::tessellateUniform(surface, options);
    const double ms = msSince(start);
    if (ms < best.ms) best = {ms, stages, std::move(mesh)};
  }
  return best;
}

bool identical(const TriangleMesh& a, const TriangleMesh& b) {
  const auto same = [](const std::vector<render::Vec3f>& x, const std::vector<render::Vec3f>& y) {
    return x.size() == y.size() &&
           std::equal(x.begin(), x.end(), y.begin(), [](const auto& p, const auto& q) {
             return p.x == q.x && p.y == q.y && p.z == q.z;
           });
  };
  return same(a.positions, b.positions) && same(a.normals, b.normals) &&
         same(a.limitPositions, b.limitPositions) && a.indices == b.indices && a.lines == b.lines;
}

}  // namespace

int main(int argc, char** argv) {
  int repeat = 3, maxLevel = 5;
  std::string only;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string flag = argv[i];
    if (flag == "--repeat") repeat = std::stoi(argv[i + 1]);
    if (flag == "--max-level") maxLevel = std::stoi(argv[i + 1]);
    if (flag == "--only") only = argv[i + 1];
  }
  std::printf(
      "| mesh | level | vertices | Far positions ms | opensubdiv ms | masks ms (refine + limit + "
      "mesh) | masks 1 thread ms | same | masks / Far positions | Mvert/s | vs 4x prev |\n");
  std::printf("|---|---:|---:|---:|---:|---|---:|:---:|---:|---:|---:|\n");
  for (const NamedMesh& named : meshes()) {
    if (named.name.find(only) == std::string::npos) continue;
    render::subdiv::LimitSurface surface(named.mesh);
    double previous = 0;
    for (int level = 1; level <= maxLevel; ++level) {
      UniformOptions options;
      options.level = level;
      options.engine = UniformEngine::Masks;
      Run masks;
      try {
        masks = tessellate(surface, options, 1);
      } catch (const std::exception&) {
        break;  // over maxTriangles
      }
      const size_t vertices = masks.mesh.vertexCount();
      const int runs = vertices > 1'000'000 ? 1 : repeat;
      masks = tessellate(surface, options, runs);
      render::parallelThreadLimit() = 1;
      Run single = tessellate(surface, options, runs);
      render::parallelThreadLimit() = 0;
      options.engine = UniformEngine::OpenSubdiv;
      Run osd = tessellate(surface, options, runs);
      const double far = minMs(runs, [&] { farPositions(named.mesh, level); });
      char growth[16] = "";
      if (previous > 0) std::snprintf(growth, sizeof growth, "%.2f", masks.ms / (4 * previous));
      std::printf(
          "| %s | %d | %zu | %.1f | %.1f | %.1f (%.1f + %.1f + %.1f) | %.1f | %s | %.2f | %.2f | "
          "%s |\n",
          named.name.c_str(), level, vertices, far, osd.ms, masks.ms, masks.stages.refineMs,
          masks.stages.limitMs, masks.stages.meshMs, single.ms,
          identical(masks.mesh, single.mesh) ? "yes" : "**no**", masks.ms / far,
          vertices / masks.ms / 1e3, growth);
      std::fflush(stdout);
      previous = masks.ms;
    }
  }
  return 0;
}
