// rules_bench: uniform refinement time per level, limn's own rules (render/rules: masks, and the
// factored form for Catmull-Clark) against OpenSubdiv in the same run, on the larger corpus
// shapes and the project's torus, up to about 2M faces. Prints a Markdown table
// (bench/rules_results.md keeps the last run).
//
// What is timed, from a ControlMesh in memory to the refined points of the last level, topology
// included on both sides:
//   OpenSubdiv  Far::TopologyRefinerFactory::Create + RefineUniform(level) +
//               PrimvarRefiner::Interpolate level by level (float weights, double points: what
//               render/tessellate/uniform.cpp does);
//   masks       rules::refineUniform(mesh, level, Masks) (base topology through the edge hash
//               map, then each level's topology and points);
//   factored    the same with Method::Factored.
// The limit columns time the last level's limit positions and tangents: Far's
// PrimvarRefiner::Limit against rules::limitOf (refinement not included).
// Each time is the minimum of --repeat runs (default 5; 2 above a million faces).
//
//   rules_bench [--repeat N] [--max-faces N] [--corpus DIR]
#include <opensubdiv/far/primvarRefiner.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "formats/obj_reader.h"
#include "render/rules/limit.h"
#include "render/rules/refine.h"
#include "render/subdiv/limit_surface.h"
#include "tests/unit/test_meshes.h"

namespace fs = std::filesystem;
namespace Far = OpenSubdiv::Far;
namespace Sdc = OpenSubdiv::Sdc;
using namespace limn;
using render::mesh::ControlMesh;
using render::mesh::Scheme;

namespace {

struct Config {
  int repeat = 5;
  double maxFaces = 2.1e6;
  std::string corpus = LIMN_SOURCE_DIR "/../shared/corpus/osd-shapes";
};

struct NamedMesh {
  std::string name;
  ControlMesh mesh;
};

// The primvar type uniform.cpp interpolates.
struct Point {
  double x = 0, y = 0, z = 0;
  void Clear(void* = nullptr) { x = y = z = 0; }
  void AddWithWeight(const Point& p, float w) {
    x += w * p.x;
    y += w * p.y;
    z += w * p.z;
  }
};

// Far's refinement: the refiner (kept for Limit) and the points of every level.
struct FarRun {
  std::unique_ptr<Far::TopologyRefiner> refiner;
  std::vector<Point> points;
  Point* last = nullptr;
};

FarRun farRefine(const ControlMesh& m, int level) {
  FarRun run;
  run.refiner = render::subdiv::createTopologyRefiner(m);
  Far::TopologyRefiner::UniformOptions options(level);
  options.fullTopologyInLastLevel = true;
  run.refiner->RefineUniform(options);
  run.points.resize(run.refiner->GetNumVerticesTotal());
  for (int v = 0; v < m.vertexCount(); ++v) {
    run.points[v] = {m.points[v].x, m.points[v].y, m.points[v].z};
  }
  Far::PrimvarRefiner primvar(*run.refiner);
  Point* src = run.points.data();
  for (int l = 1; l <= level; ++l) {
    Point* dst = src + run.refiner->GetLevel(l - 1).GetNumVertices();
    primvar.Interpolate(l, src, dst);
    src = dst;
  }
  run.last = src;
  return run;
}

double minMs(int repeat, const std::function<void()>& work) {
  double best = 1e300;
  for (int r = 0; r < repeat; ++r) {
    auto start = std::chrono::steady_clock::now();
    work();
    best = std::min(
        best, std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                  .count());
  }
  return best;
}

double faceCount(const ControlMesh& m, int level) {
  double faces = 0;
  for (int n : m.faceVertexCounts) {
    faces += m.scheme == Scheme::Loop ? 1.0 : (level == 0 ? 1.0 : n / 4.0);
  }
  for (int l = 0; l < level; ++l) faces *= 4;
  return faces;
}

std::vector<NamedMesh> loadMeshes(const Config& config) {
  std::vector<NamedMesh> meshes;
  for (const char* name : {"catmark_xord_interior", "catmark_single_crease", "catmark_quadstrips",
                           "catmark_smoothtris0", "loop_xord_interior", "loop_icos_semisharp"}) {
    fs::path path = fs::path(config.corpus) / (std::string(name) + ".obj");
    if (!fs::exists(path)) continue;
    std::ifstream file(path);
    std::ostringstream text;
    text << file.rdbuf();
    Scheme scheme = std::string(name).rfind("loop_", 0) == 0 ? Scheme::Loop : Scheme::CatmullClark;
    meshes.push_back({name, formats::readObj(text.str(), scheme, {}).mesh});
  }
  meshes.push_back({"torus 40x25 (own)", testing::torus(40, 25, false)});
  meshes.push_back({"torus 12x8 creased (own)", testing::torus(12, 8, true)});
  return meshes;
}

std::string ratio(double a, double b) {
  char text[32];
  std::snprintf(text, sizeof text, "%.2f", a / b);
  return text;
}

}  // namespace

int main(int argc, char** argv) {
  Config config;
  for (int i = 1; i + 1 < argc; i += 2) {
    std::string flag = argv[i];
    if (flag == "--repeat")
      config.repeat = std::stoi(argv[i + 1]);
    else if (flag == "--max-faces")
      config.maxFaces = std::stod(argv[i + 1]);
    else if (flag == "--corpus")
      config.corpus = argv[i + 1];
  }

  std::printf(
      "| shape | level | faces | OpenSubdiv ms | masks ms | masks / OSD | factored ms | "
      "factored / OSD | OSD limit ms | own limit ms | own / OSD |\n");
  std::printf("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  for (const NamedMesh& shape : loadMeshes(config)) {
    const bool factored =
        render::rules::unsupportedReason(shape.mesh, render::rules::Method::Factored).empty();
    for (int level = 1; faceCount(shape.mesh, level) <= config.maxFaces; ++level) {
      const double faces = faceCount(shape.mesh, level);
      const int repeat = faces > 1e6 ? std::min(config.repeat, 2) : config.repeat;
      double far = minMs(repeat, [&] { farRefine(shape.mesh, level); });
      double masks = minMs(repeat, [&] {
        render::rules::refineUniform(shape.mesh, level, render::rules::Method::Masks);
      });
      std::string factoredMs = "n/a", factoredRatio = "n/a";
      if (factored) {
        double ms = minMs(repeat, [&] {
          render::rules::refineUniform(shape.mesh, level, render::rules::Method::Factored);
        });
        char text[32];
        std::snprintf(text, sizeof text, "%.1f", ms);
        factoredMs = text;
        factoredRatio = ratio(ms, far);
      }
      // Limits of the last level, refinement not timed.
      FarRun run = farRefine(shape.mesh, level);
      const int n = run.refiner->GetLevel(level).GetNumVertices();
      std::vector<Point> limit(n), tan1(n), tan2(n);
      double farLimit = minMs(
          repeat, [&] { Far::PrimvarRefiner(*run.refiner).Limit(run.last, limit, tan1, tan2); });
      render::rules::Level own =
          render::rules::refineUniform(shape.mesh, level, render::rules::Method::Masks);
      double ownLimit = minMs(repeat, [&] { render::rules::limitOf(own); });
      std::printf("| %s | %d | %.0f | %.1f | %.1f | %s | %s | %s | %.1f | %.1f | %s |\n",
                  shape.name.c_str(), level, faces, far, masks, ratio(masks, far).c_str(),
                  factoredMs.c_str(), factoredRatio.c_str(), farLimit, ownLimit,
                  ratio(ownLimit, farLimit).c_str());
      std::fflush(stdout);
    }
  }
  return 0;
}
