// reference_bench: where the exact reference spends its time, stage by stage, next to the
// adaptive approximation (dicingRate 1) of the same request measured in the same run, on the
// project's own dense meshes and the corpus shapes over ~500 faces (the corpus has none today;
// --shapes adds any). Prints Markdown (bench/reference_results.md keeps the last run).
//
//   reference_bench [--size 1024] [--supersample 4] [--repeat 3] [--corpus DIR] [--shapes a,b]
//
// Each row is the best of --repeat warm runs. "adaptive ms" is approximation + raster of the
// request without a reference; "ratio" is referenceMs / adaptive ms; the stage columns split
// referenceMs (ms); "cache hit ms" is referenceMs when the tessellation and BVH come from the
// reference cache (the same request again).
#include <algorithm>
#include <cstdio>
#include <string>
#include <thread>
#include <vector>

#include "bench/bench_common.h"
#include "render/pipeline/render_job.h"
#include "render/raster/rasterizer.h"
#include "tests/unit/test_meshes.h"

using namespace limn;
using render::pipeline::Method;
using render::pipeline::RenderJob;
using render::pipeline::RenderResult;

namespace {

struct NamedMesh {
  std::string name;
  render::mesh::ControlMesh mesh;
};

struct Config {
  int size = 1024;
  int supersample = 4;
  int repeat = 3;
  bool crossCheck = false;
  std::string corpus = LIMN_SOURCE_DIR "/../shared/corpus/osd-shapes";
  std::vector<std::string> shapes;
};

std::vector<NamedMesh> loadMeshes(const Config& config) {
  std::vector<NamedMesh> meshes = {
      {"pawn (own, 560 faces)", testing::pawn()},
      {"torus 40x25 (own, 1000 faces)", testing::torus(40, 25, false)},
      {"bumpy ball (own, 1536 faces)", testing::bumpyBall(16)},
  };
  for (const std::string& shape : config.shapes) {
    if (auto mesh = bench::readShape(config.corpus, shape)) meshes.push_back({shape, *mesh});
  }
  return meshes;
}

RenderJob adaptiveJob(const NamedMesh& m, const Config& config) {
  RenderJob job;
  job.mesh = m.mesh;
  job.camera.width = job.camera.height = config.size;
  job.method = Method::Adaptive;
  job.params.dicingRate = 1.0;
  job.params.metricSupersample = config.supersample;
  job.params.referenceCrossCheck = config.crossCheck;
  return job;
}

}  // namespace

int main(int argc, char** argv) {
  Config config;
  for (int i = 1; i < argc; ++i) {
    std::string flag = argv[i];
    if (flag == "--cross-check") {
      config.crossCheck = true;
      continue;
    }
    if (i + 1 >= argc) {
      std::fprintf(stderr, "%s needs a value\n", flag.c_str());
      return 2;
    }
    std::string value = argv[++i];
    if (flag == "--size")
      config.size = std::stoi(value);
    else if (flag == "--supersample")
      config.supersample = std::stoi(value);
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
  render::oracle::ReferenceSceneCache cache(size_t{1} << 30);
  render::pipeline::RenderContext context{.rasterizer = &rasterizer, .referenceCache = &cache};
  std::printf("renderer: %s; %u hardware threads; %d x %d, S = %d; best of %d warm runs%s\n\n",
              rasterizer.device().renderer.c_str(), std::thread::hardware_concurrency(),
              config.size, config.size, config.supersample, config.repeat,
              config.crossCheck ? "; with the Embree subdivision cross-check" : "");

  std::printf(
      "| mesh | faces | adaptive ms | reference ms | ratio | ref. triangles | tessellate | "
      "BVH | primary rays | Newton+shade | S-mask rays | outline | cross-check | metrics ms | "
      "cache hit ms | hit ratio | outlineHausdorffPx |\n");
  std::printf(
      "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  for (const NamedMesh& m : loadMeshes(config)) {
    try {
      RenderJob job = adaptiveJob(m, config);
      RenderResult plain = bench::runBest(job, context, config.repeat);
      double adaptiveMs = plain.timings.approxMs + plain.timings.rasterMs;
      job.reference = true;
      RenderResult r = bench::runBest(job, context, config.repeat, [&] { cache.clear(); });
      RenderResult hit = bench::runBest(job, context, config.repeat);  // the scene stays cached
      const render::oracle::ReferenceStats& st = *r.timings.reference;
      std::printf(
          "| %s | %d | %.0f | %.0f | %.2f | %zu | %.0f | %.0f | %.0f | %.0f | %.0f | %.0f | "
          "%.0f | %.0f | %.0f | %.2f | %.3f |\n",
          m.name.c_str(), m.mesh.faceCount(), adaptiveMs, r.timings.referenceMs,
          r.timings.referenceMs / adaptiveMs, st.triangles, st.tessellateMs, st.bvhMs, st.traceMs,
          st.newtonMs, st.maskMs, st.outlineMs, r.timings.crossCheckMs, r.timings.metricsMs,
          hit.timings.referenceMs, hit.timings.referenceMs / adaptiveMs,
          r.metrics.silhouette->outlineHausdorffPx.value_or(-1));
    } catch (const std::exception& e) {
      std::printf("| %s | %d | failed: %s |\n", m.name.c_str(), m.mesh.faceCount(), e.what());
    }
    std::fflush(stdout);
  }
  return 0;
}
