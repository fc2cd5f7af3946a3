// render_bench: per-stage times and triangle counts of every method on the project's meshes and
// the corpus, at several image sizes, plus the reference's cost and the silhouette error.
// Prints Markdown tables (bench/results.md keeps the last run). Times are warm: each
// configuration runs once to warm up, then the best of --repeat runs is reported.
//
//   render_bench [--sizes 512,1024] [--repeat 3] [--corpus DIR] [--shapes a,b,...]
#include <algorithm>
#include <cstdio>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "bench/bench_common.h"
#include "render/pipeline/render_job.h"
#include "render/raster/rasterizer.h"
#include "tests/unit/test_meshes.h"

using namespace limn;
using render::pipeline::Method;

namespace {

struct NamedMesh {
  std::string name;
  render::mesh::ControlMesh mesh;
};

struct Config {
  std::vector<int> sizes{512, 1024};
  int repeat = 3;
  std::string corpus = LIMN_SOURCE_DIR "/../shared/corpus/osd-shapes";
  std::vector<std::string> shapes{"catmark_cube_creases1", "catmark_torus_creases0",
                                  "catmark_gregory_test1", "loop_icos_semisharp", "loop_pole8"};
};

std::vector<int> parseInts(const std::string& list) {
  std::vector<int> out;
  std::stringstream in(list);
  for (std::string item; std::getline(in, item, ',');) out.push_back(std::stoi(item));
  return out;
}

std::vector<NamedMesh> loadMeshes(const Config& config) {
  std::vector<NamedMesh> meshes = {
      {"cube (own)", testing::cube()},
      {"torus 12x8 creased (own)", testing::torus(12, 8, true)},
      {"torus 40x25, 1000 faces (own)", testing::torus(40, 25, false)},
      {"icosahedron loop (own)", testing::icosahedron()},
  };
  for (const std::string& shape : config.shapes) {
    if (auto mesh = bench::readShape(config.corpus, shape)) meshes.push_back({shape, *mesh});
  }
  return meshes;
}

struct Variant {
  std::string label;
  Method method;
  int level = 0;
};

}  // namespace

int main(int argc, char** argv) {
  Config config;
  for (int i = 1; i + 1 < argc; i += 2) {
    std::string flag = argv[i], value = argv[i + 1];
    if (flag == "--sizes")
      config.sizes = parseInts(value);
    else if (flag == "--repeat")
      config.repeat = std::stoi(value);
    else if (flag == "--corpus")
      config.corpus = value;
    else if (flag == "--shapes")
      config.shapes = bench::splitList(value);
    else {
      std::fprintf(stderr, "unknown flag %s\n", flag.c_str());
      return 2;
    }
  }
  render::raster::Rasterizer rasterizer;
  render::pipeline::RenderContext context{.rasterizer = &rasterizer};
  std::printf("renderer: %s; %u hardware threads; warm times, best of %d\n\n",
              rasterizer.device().renderer.c_str(), std::thread::hardware_concurrency(),
              config.repeat);

  const std::vector<Variant> variants = {{"coarse", Method::Coarse},
                                         {"uniform L1", Method::Uniform, 1},
                                         {"uniform L3", Method::Uniform, 3},
                                         {"adaptive dr1", Method::Adaptive}};
  std::vector<NamedMesh> meshes = loadMeshes(config);

  std::printf("## Approximations (color+mask+depth+normal, no reference)\n\n");
  std::printf(
      "| mesh | faces | size | method | triangles | surface ms | approx ms | raster ms | total ms "
      "|\n");
  std::printf("|---|---:|---:|---|---:|---:|---:|---:|---:|\n");
  for (const NamedMesh& m : meshes) {
    for (int size : config.sizes) {
      for (const Variant& v : variants) {
        render::pipeline::RenderJob job;
        job.mesh = m.mesh;
        job.camera.width = size;
        job.camera.height = size;
        job.method = v.method;
        job.params.level = v.level;
        job.outputs = {.color = true, .mask = true, .depth = true, .normal = true};
        try {
          auto r = bench::runBest(job, context, config.repeat);
          std::printf("| %s | %d | %d | %s | %zu | %.1f | %.1f | %.1f | %.1f |\n", m.name.c_str(),
                      m.mesh.faceCount(), size, v.label.c_str(), r.stats.triangles,
                      r.timings.surfaceMs, r.timings.approxMs, r.timings.rasterMs,
                      r.timings.totalMs);
        } catch (const std::exception& e) {
          std::printf("| %s | %d | %d | %s | failed: %s |||||\n", m.name.c_str(),
                      m.mesh.faceCount(), size, v.label.c_str(), e.what());
        }
        std::fflush(stdout);
      }
    }
  }

  std::printf(
      "\n## Reference and metrics (adaptive dr1 with reference: true, S = 4, "
      "referenceCrossCheck: true)\n\n");
  std::printf(
      "| mesh | size | reference triangles | reference ms | metrics ms | total ms | "
      "hausdorffPx | crossCheckPx |\n");
  std::printf("|---|---:|---:|---:|---:|---:|---:|---:|\n");
  for (const NamedMesh& m : meshes) {
    for (int size : config.sizes) {
      render::pipeline::RenderJob job;
      job.mesh = m.mesh;
      job.camera.width = size;
      job.camera.height = size;
      job.method = Method::Adaptive;
      job.reference = true;
      job.params.referenceCrossCheck = true;
      try {
        auto r = bench::runBest(job, context, std::max(1, config.repeat / 2));
        std::string cross = r.stats.referenceCrossCheckPx
                                ? std::to_string(*r.stats.referenceCrossCheckPx).substr(0, 5)
                                : "n/a";
        std::printf("| %s | %d | %zu | %.1f | %.1f | %.1f | %.3f | %s |\n", m.name.c_str(), size,
                    r.stats.referenceTriangles, r.timings.referenceMs, r.timings.metricsMs,
                    r.timings.totalMs, r.metrics.silhouette->hausdorffPx, cross.c_str());
      } catch (const std::exception& e) {
        std::printf("| %s | %d | failed: %s ||||||\n", m.name.c_str(), size, e.what());
      }
      std::fflush(stdout);
    }
  }
  return 0;
}
