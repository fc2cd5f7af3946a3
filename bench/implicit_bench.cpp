// The polygonisers on the sample scenes of configs/implicit: time, triangles, vertices and
// geometric error per method and resolution, and the adaptive-vs-finer-grid comparison.
//
//   implicit_bench [--resolutions 80,120,360] [--scenes a,b]
//       the tables of bench/implicit_results.md
//   implicit_bench --dump SCENE RESOLUTION FILE
//       samples the field on the marching-cubes grid (all threads; timed) and writes it to FILE
//       as float32 [z][y][x] (bench/implicit_vs_peers.py gives the same file to VTK and
//       scikit-image); prints one JSON line
//   implicit_bench --march SCENE RESOLUTION FILE [--threads 1] [--slab 0] [--runs 5]
//       times marching cubes alone on FILE's samples (vertices by linear interpolation, as VTK
//       and scikit-image place them), on at most --threads threads; prints one JSON line
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "api/implicit_api.h"
#include "bench/bench_common.h"
#include "render/core/parallel.h"
#include "render/implicit/grid.h"
#include "render/implicit/polygonize.h"

namespace {

using namespace limn;
using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

render::implicit::FieldSpec sceneField(const std::string& name) {
  std::ifstream in(std::string(LIMN_SOURCE_DIR) + "/configs/implicit/" + name + ".json");
  if (!in) throw std::runtime_error("no scene configs/implicit/" + name + ".json");
  std::stringstream text;
  text << in.rdbuf();
  return api::parseImplicitRequest(text.str(), {}).job.field;
}

struct Row {
  double ms = 0;
  size_t triangles = 0, vertices = 0;
  render::implicit::ImplicitGeometryError error;
  bool closed = false;
};

Row polygonise(const render::implicit::Field& field, render::implicit::PolygonizerMethod method,
               int resolution, double flatness = 0.9) {
  render::implicit::PolygonizerOptions options;
  options.method = method;
  options.resolution = resolution;
  options.flatness = flatness;
  Row best;
  for (int run = 0; run < 3; ++run) {
    const auto start = Clock::now();
    render::implicit::Polygonization p = render::implicit::polygonize(field, options, {});
    const double ms = msSince(start);
    if (run == 0 || ms < best.ms) {
      best.ms = ms;
      best.triangles = p.mesh.triangleCount();
      best.vertices = p.mesh.vertexCount();
      best.error = render::implicit::measureImplicitGeometry(p.mesh, field, {});
      best.closed = render::implicit::checkClosure(p.mesh).closed();
    }
    if (ms > 2000) break;  // large grids: one run is enough
  }
  return best;
}

void printRow(const std::string& scene, const char* method, int resolution, const char* extra,
              const Row& r) {
  std::printf("| %s | %s%s | %d | %.1f | %zu | %zu | %.2e | %.2e | %s |\n", scene.c_str(), method,
              extra, resolution, r.ms, r.triangles, r.vertices, r.error.relMaxDist,
              r.error.relMeanDist, r.closed ? "yes" : "**no**");
}

int tables(const std::vector<std::string>& scenes, const std::vector<int>& resolutions) {
  using render::implicit::PolygonizerMethod;
  const PolygonizerMethod methods[] = {PolygonizerMethod::MarchingCubes, PolygonizerMethod::Tracker,
                                       PolygonizerMethod::Octree, PolygonizerMethod::Adaptive};
  std::printf(
      "| scene | method | resolution | ms | triangles | vertices | max error | mean error "
      "| closed |\n|---|---|---:|---:|---:|---:|---:|---:|---|\n");
  for (const std::string& scene : scenes) {
    const render::implicit::Field field(sceneField(scene));
    for (int resolution : resolutions) {
      for (PolygonizerMethod method : methods) {
        printRow(scene, render::implicit::polygonizerName(method), resolution, "",
                 polygonise(field, method, resolution));
        std::fflush(stdout);
      }
    }
  }
  // Adaptive from a coarse grid against plain marching cubes on finer grids: the finest grid
  // whose largest error adaptive still matches (the geometric error as a distance bound), and
  // the triangle ratio; mean errors alongside.
  std::printf(
      "\n| scene | adaptive: resolution, flatness | triangles | max error | mean error "
      "| finest marching-cubes grid it matches | its triangles | its max error | its mean "
      "error | triangle ratio |\n|---|---|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  for (const std::string& scene : scenes) {
    const render::implicit::Field field(sceneField(scene));
    for (const auto& [resolution, flatness] :
         std::vector<std::pair<int, double>>{{60, 0.9}, {80, 0.9}, {80, 0.97}}) {
      const Row adaptive = polygonise(field, PolygonizerMethod::Adaptive, resolution, flatness);
      Row matched;
      int matchedResolution = 0;
      for (int finer = resolution; finer <= 480; finer += 20) {
        Row mc = polygonise(field, PolygonizerMethod::MarchingCubes, finer);
        if (mc.error.relMaxDist < adaptive.error.relMaxDist) break;
        matched = mc;
        matchedResolution = finer;
      }
      std::printf("| %s | %d, %.2f | %zu | %.2e | %.2e | %s | %zu | %.2e | %.2e | %.2f |\n",
                  scene.c_str(), resolution, flatness, adaptive.triangles,
                  adaptive.error.relMaxDist, adaptive.error.relMeanDist,
                  matchedResolution ? std::to_string(matchedResolution).c_str() : "none",
                  matched.triangles, matched.error.relMaxDist, matched.error.relMeanDist,
                  matched.triangles ? double(adaptive.triangles) / matched.triangles : 0.0);
      std::fflush(stdout);
    }
  }
  return 0;
}

int dump(const std::string& scene, int resolution, const std::string& path) {
  const render::implicit::Field field(sceneField(scene));
  const render::implicit::Grid grid = render::implicit::makeGrid(field.bounds(), resolution);
  std::vector<float> values(grid.cornersPerLayer() * (grid.n[2] + 1));
  const auto start = Clock::now();
  render::implicit::sampleLayers(field, grid, 0, grid.n[2], values.data(), {});
  const double sampleMs = msSince(start);
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(values.data()),
            static_cast<std::streamsize>(values.size() * sizeof(float)));
  std::printf(
      "{\"scene\":\"%s\",\"resolution\":%d,\"shape\":[%d,%d,%d],\"sampleMs\":%.3f,"
      "\"mvoxelsPerS\":%.2f}\n",
      scene.c_str(), resolution, grid.n[2] + 1, grid.n[1] + 1, grid.n[0] + 1, sampleMs,
      values.size() / (sampleMs * 1e3));
  return 0;
}

// Marching cubes on samples written by dump: the cells' triangles and the vertices by linear
// interpolation (as scikit-image and VTK place them), slabs of `slab` layers (0: the whole grid
// at once), on at most `threads` threads. Only polygonisation is timed, best of `runs`.
int march(const std::string& scene, int resolution, const std::string& path, unsigned threads,
          int slab, int runs) {
  const render::implicit::Field field(sceneField(scene));
  const render::implicit::Grid grid = render::implicit::makeGrid(field.bounds(), resolution);
  const size_t perLayer = grid.cornersPerLayer();
  std::vector<float> values(perLayer * (grid.n[2] + 1));
  std::ifstream in(path, std::ios::binary);
  in.read(reinterpret_cast<char*>(values.data()),
          static_cast<std::streamsize>(values.size() * sizeof(float)));
  if (!in) throw std::runtime_error(path + " does not hold this scene's grid");
  render::parallelThreadLimit() = threads;
  if (slab <= 0) slab = grid.n[2];
  double best = 1e300;
  size_t triangles = 0, vertices = 0;
  // The output's buffers are kept from run to run (as a VTK filter keeps its output object):
  // on this machine first touching fresh memory costs about 4 ms per MB, more than the work.
  render::implicit::RawMesh raw;
  std::vector<render::Vec3f> positions;
  for (int run = 0; run < runs; ++run) {
    raw.vertices.clear();
    raw.indices.clear();
    const auto start = Clock::now();
    render::implicit::SlabMarcher marcher(grid, raw);
    for (int k0 = 0; k0 < grid.n[2]; k0 += slab) {
      marcher.march(k0, std::min(grid.n[2], k0 + slab), &values[k0 * perLayer]);
    }
    positions.resize(raw.vertices.size());
    render::parallelFor(raw.vertices.size(), 4096, [&](size_t begin, size_t end) {
      for (size_t v = begin; v < end; ++v) {
        const auto& e = raw.vertices[v];
        positions[v] = render::Vec3f(e.a + (e.b - e.a) * (e.fa / (e.fa - e.fb)));
      }
    });
    best = std::min(best, msSince(start));
    triangles = raw.indices.size() / 3;
    vertices = positions.size();
  }
  std::printf("{\"threads\":%u,\"slab\":%d,\"ms\":%.3f,\"triangles\":%zu,\"vertices\":%zu}\n",
              threads, slab, best, triangles, vertices);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> scenes = {"sphere_bite", "metaball_figure", "sphere_cylinder_cut"};
  std::vector<int> resolutions = {80, 120, 360};
  for (int i = 1; i < argc; ++i) {
    std::string arg = argv[i];
    if (arg == "--dump" && i + 3 < argc)
      return dump(argv[i + 1], std::stoi(argv[i + 2]), argv[i + 3]);
    if (arg == "--march" && i + 3 < argc) {
      unsigned threads = 1;
      int slab = 0, runs = 5;
      for (int o = i + 4; o + 1 < argc; o += 2) {
        const std::string option = argv[o];
        if (option == "--threads") threads = static_cast<unsigned>(std::stoi(argv[o + 1]));
        if (option == "--slab") slab = std::stoi(argv[o + 1]);
        if (option == "--runs") runs = std::stoi(argv[o + 1]);
      }
      return march(argv[i + 1], std::stoi(argv[i + 2]), argv[i + 3], threads, slab, runs);
    }
    if (arg == "--scenes" && i + 1 < argc) scenes = bench::splitList(argv[++i]);
    if (arg == "--resolutions" && i + 1 < argc) {
      resolutions.clear();
      for (const std::string& r : bench::splitList(argv[++i])) resolutions.push_back(std::stoi(r));
    }
  }
  return tables(scenes, resolutions);
}
