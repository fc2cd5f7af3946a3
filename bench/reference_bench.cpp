// reference_bench: what a comparison (`reference: true`) costs next to the plain render of the
// same request (adaptive, dicingRate 1), measured in the same run, stage by stage: on the
// project's own dense meshes (pawn, torus, bumpy ball, a Loop creature, a 5k-face creature, an
// 80k-face torus), make_models.py's models (--model-dir, --models) and corpus shapes (--shapes).
// Prints Markdown (bench/reference_results.md keeps the runs).
//
//   reference_bench [--size 1024] [--supersample 4] [--repeat 3] [--only prefix,...]
//                   [--model-dir DIR --models a,b] [--corpus DIR --shapes a,b] [--cross-check]
//   reference_bench --values ...   every metric of 3 views x 3 methods per mesh, exactly
//
// Each row is the best (totalMs) of --repeat warm runs. "plain ms" is totalMs without the
// reference (approximation + raster, colour only; no encoding); "compared ms" is totalMs with it
// (the approximation's extra passes and 4096^2 mask, the reference, the metrics), every run
// building its reference scene anew (the cache emptied); "ratio" is compared / plain. The
// reference columns split referenceMs, the metrics columns metricsMs (ms).
#include <algorithm>
#include <cstdio>
#include <fstream>
#include <optional>
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
  bool values = false;
  std::string corpus = LIMN_SOURCE_DIR "/../shared/corpus/osd-shapes";
  std::vector<std::string> shapes;
  std::string modelDir;
  std::vector<std::string> models, only;
};

// A make_models.py model: `dir`/`name`.obj, its scheme named on a "# scheme" line.
std::optional<render::mesh::ControlMesh> readModel(const std::string& dir,
                                                   const std::string& name) {
  std::ifstream file(dir + "/" + name + ".obj");
  if (!file) return std::nullopt;
  std::stringstream text;
  text << file.rdbuf();
  const std::string obj = text.str();
  render::mesh::Scheme scheme = render::mesh::Scheme::CatmullClark;
  if (obj.find("# scheme loop") != std::string::npos) scheme = render::mesh::Scheme::Loop;
  return formats::readObj(obj, scheme, {}).mesh;
}

std::vector<NamedMesh> ownMeshes() {
  return {
      {"pawn (own)", testing::pawn()},
      {"torus 40x25 (own)", testing::torus(40, 25, false)},
      {"bumpy ball (own)", testing::bumpyBall(16)},
      {"Loop creature(11) (own)", testing::loopCreature(11)},
      {"creature(29) (own)", testing::creature(29)},
      {"torus 400x200 (own)", testing::torus(400, 200, false)},
  };
}

// --only picks rows by name prefix; --models adds make_models.py's OBJ files (scheme from the
// file's "# scheme" line).
std::vector<NamedMesh> loadMeshes(const Config& config) {
  std::vector<NamedMesh> meshes;
  for (NamedMesh& m : ownMeshes()) meshes.push_back(std::move(m));
  for (const std::string& shape : config.shapes) {
    if (auto mesh = bench::readShape(config.corpus, shape)) meshes.push_back({shape, *mesh});
  }
  for (const std::string& model : config.models) {
    if (auto mesh = readModel(config.modelDir, model)) meshes.push_back({model, *mesh});
  }
  if (config.only.empty()) return meshes;
  std::vector<NamedMesh> picked;
  for (NamedMesh& m : meshes) {
    for (const std::string& prefix : config.only) {
      if (m.name.rfind(prefix, 0) == 0) {
        picked.push_back(std::move(m));
        break;
      }
    }
  }
  return picked;
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

// Every metric of one comparison, printed exactly (%.17g), so that two builds' outputs can be
// compared with diff: `--values` checks that a change to the metrics' speed left them unchanged.
void printValues(const std::string& label, const render::metrics::Metrics& m) {
  const auto& s = *m.silhouette;
  std::printf("%s sil %.17g %.17g %.17g %ld outline %.17g %.17g\n", label.c_str(), s.hausdorffPx,
              s.meanPx, s.iou, s.mismatchPx, s.outlineHausdorffPx.value_or(-1),
              s.outlineMeanPx.value_or(-1));
  std::printf("%s image %.17g %.17g depth %.17g %.17g normal %.17g %.17g\n", label.c_str(),
              m.image->rmse, m.image->psnr, m.depth->maxRel, m.depth->meanRel, m.normal->meanDeg,
              m.normal->maxDeg);
  std::printf("%s geometry %.17g %.17g %.17g %.17g\n", label.c_str(), m.geometry->maxDist,
              m.geometry->meanDist, m.geometry->relMaxDist, m.geometry->relMeanDist);
}

// Each mesh from three views with three methods at the bench's size, every metric printed.
void printAllValues(const Config& config, render::pipeline::RenderContext& context) {
  const std::pair<Method, double> methods[] = {
      {Method::Adaptive, 1.0}, {Method::Adaptive, 8.0}, {Method::Coarse, 1.0}};
  const render::Orbit views[] = {{0, 0, {}}, {37, 24, {}}, {-120, -35, 1.6}};
  render::pipeline::JobLimits limits;
  for (const NamedMesh& m : loadMeshes(config)) {
    for (const render::Orbit& view : views) {
      for (auto [method, rate] : methods) {
        RenderJob job = adaptiveJob(m, config);
        job.method = method;
        job.params.dicingRate = rate;
        job.camera.orbit = view;
        job.reference = true;
        char label[256];
        std::snprintf(label, sizeof label, "%s az%g el%g m%d r%g |", m.name.c_str(),
                      view.azimuthDeg, view.elevationDeg, static_cast<int>(method), rate);
        try {
          printValues(label, render::pipeline::run(job, limits, context, {}).metrics);
        } catch (const std::exception& e) {
          std::printf("%s failed: %s\n", label, e.what());
        }
        std::fflush(stdout);
      }
    }
  }
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
    if (flag == "--values") {
      config.values = true;
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
    else if (flag == "--model-dir")
      config.modelDir = value;
    else if (flag == "--models")
      config.models = bench::splitList(value);
    else if (flag == "--only")
      config.only = bench::splitList(value);
    else {
      std::fprintf(stderr, "unknown flag %s\n", flag.c_str());
      return 2;
    }
  }
  render::raster::Rasterizer rasterizer;
  render::oracle::ReferenceSceneCache cache(size_t{1} << 30);
  render::pipeline::RenderContext context{
      .rasterizer = &rasterizer, .referenceCache = &cache, .gpuTessellator = nullptr};
  if (config.values) {
    printAllValues(config, context);
    return 0;
  }
  std::printf("renderer: %s; %u hardware threads; %d x %d, S = %d; best of %d warm runs%s\n\n",
              rasterizer.device().renderer.c_str(), std::thread::hardware_concurrency(),
              config.size, config.size, config.supersample, config.repeat,
              config.crossCheck ? "; with the Embree subdivision cross-check" : "");

  std::printf(
      "| mesh | faces | approx. triangles | plain ms | compared ms | ratio | approx+raster | "
      "reference ms | metrics ms | ref. triangles | tessellate | BVH | primary rays | "
      "Newton+shade | S-mask rays | outline | mask metrics | outline metrics | image metrics | "
      "geometry | outlineHausdorffPx |\n");
  std::printf(
      "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
      "---:|---:|---:|\n");
  for (const NamedMesh& m : loadMeshes(config)) {
    try {
      RenderJob job = adaptiveJob(m, config);
      RenderResult plain = bench::runBest(job, context, config.repeat);
      const double plainMs = plain.timings.totalMs;
      job.reference = true;
      RenderResult r = bench::runBest(job, context, config.repeat, [&] { cache.clear(); });
      const render::oracle::ReferenceStats& st = *r.timings.reference;
      const render::metrics::MetricsTimings mt =
          r.timings.metricsStages.value_or(render::metrics::MetricsTimings{});
      std::printf(
          "| %s | %d | %zu | %.0f | %.0f | %.2f | %.0f | %.0f | %.0f | %zu | %.0f | %.0f | %.0f | "
          "%.0f | %.0f | %.0f | %.0f | %.0f | %.0f | %.0f | %.3f |\n",
          m.name.c_str(), m.mesh.faceCount(), plain.stats.triangles, plainMs, r.timings.totalMs,
          r.timings.totalMs / plainMs, r.timings.approxMs + r.timings.rasterMs,
          r.timings.referenceMs, r.timings.metricsMs, st.triangles, st.tessellateMs, st.bvhMs,
          st.traceMs, st.newtonMs, st.maskMs, st.outlineMs, mt.silhouetteMs, mt.outlineMs,
          mt.imageMs, mt.geometryMs, r.metrics.silhouette->outlineHausdorffPx.value_or(-1));
    } catch (const std::exception& e) {
      std::printf("| %s | %d | failed: %s |\n", m.name.c_str(), m.mesh.faceCount(), e.what());
    }
    std::fflush(stdout);
  }
  return 0;
}
