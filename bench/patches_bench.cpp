// patches_bench: the patches method (render/patches) on every shape (the project's own and the
// shared corpus's, when it is there). Prints Markdown (bench/patches_results.md keeps the last
// run):
//   1. patches per isolation level 1-6 against the faces uniform refinement makes at the same
//      level, and the table's build time;
//   2. patches against adaptive at the same dicing rates from seeded random views: triangles,
//      approximation time and hausdorffPx against the exact reference;
//   3. animation: per-frame time of breathing meshes with the table and the first frame's
//      tessellation kept (vertices re-evaluated), the table kept (tessellated anew), and both
//      rebuilt every frame.
//
//   patches_bench [--size 512] [--views 2] [--seed 1] [--rates 1,4] [--frames 30]
//                 [--shapes a,b,...] [--skip-compare]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "render/patches/patch_set.h"
#include "render/patches/patch_tessellation.h"
#include "render/pipeline/compare.h"
#include "render/raster/rasterizer.h"
#include "render/subdiv/limit_surface.h"
#include "tests/support/random_views.h"
#include "tests/support/shapes.h"
#include "tests/unit/test_meshes.h"

using namespace limn;
using namespace limn::render;

namespace {

struct Options {
  int size = 512, views = 2, frames = 30;
  uint64_t seed = 1;
  std::vector<double> rates = {1, 4};
  std::vector<std::string> shapes;
  bool compare = true;
};

std::vector<std::string> split(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream in(text);
  for (std::string item; std::getline(in, item, ',');) out.push_back(item);
  return out;
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    std::string flag = argv[i];
    if (flag == "--skip-compare") {
      o.compare = false;
      continue;
    }
    if (i + 1 >= argc) throw std::runtime_error("missing value after " + flag);
    std::string value = argv[++i];
    if (flag == "--size")
      o.size = std::stoi(value);
    else if (flag == "--views")
      o.views = std::stoi(value);
    else if (flag == "--seed")
      o.seed = std::stoull(value);
    else if (flag == "--frames")
      o.frames = std::stoi(value);
    else if (flag == "--shapes")
      o.shapes = split(value);
    else if (flag == "--rates") {
      o.rates.clear();
      for (const std::string& r : split(value)) o.rates.push_back(std::stod(r));
    } else {
      throw std::runtime_error("unknown flag " + flag);
    }
  }
  return o;
}

double msSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

// Faces uniform refinement makes at `level`: Catmull-Clark splits an n-gon into n quads, then
// every quad into 4; Loop splits every triangle into 4.
double uniformFaces(const mesh::ControlMesh& m, int level) {
  double first = 0;
  for (int n : m.faceVertexCounts) first += m.scheme == mesh::Scheme::Loop || n == 4 ? 4 : n;
  return first * std::pow(4.0, level - 1);
}

void printPatchCounts(const std::vector<testing::NamedMesh>& shapes) {
  std::printf("## Patches per isolation level against uniform faces\n\n");
  std::printf(
      "Each cell: patches at that isolation / faces of uniform refinement at that "
      "level. Build: topology, adaptive refinement, patch table and point stencils.\n\n");
  std::printf(
      "| shape | faces | iso 1 | iso 2 | iso 3 | iso 4 | iso 5 | iso 6 | build ms iso 4 | "
      "build ms iso 6 |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  for (const testing::NamedMesh& shape : shapes) {
    try {
      std::printf("| %s | %d", shape.name.c_str(), shape.mesh.faceCount());
      double build4 = 0, build6 = 0;
      for (int isolation = 1; isolation <= 6; ++isolation) {
        auto start = std::chrono::steady_clock::now();
        patches::PatchSet set(shape.mesh, isolation, CancelToken());
        double ms = msSince(start);
        if (isolation == 4) build4 = ms;
        if (isolation == 6) build6 = ms;
        std::printf(" | %zu / %.0f", set.stats().patches, uniformFaces(shape.mesh, isolation));
      }
      std::printf(" | %.1f | %.1f |\n", build4, build6);
    } catch (const std::exception& e) {
      std::printf(" | failed: %s |\n", e.what());
    }
  }
  std::printf("\n");
}

struct MethodRow {
  std::string shape, method;
  double rate = 0;
  std::vector<double> px, ms, triangles;
};

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

void printComparison(const std::vector<testing::NamedMesh>& shapes, const Options& options,
                     pipeline::RenderContext& context) {
  std::printf("## patches against adaptive at the same dicing rate\n\n");
  std::printf(
      "%d random views per shape at %d x %d (seed %llu), S = 4; medians over the views, "
      "worst px in brackets. Time: approximation only (the raster is the same work per "
      "triangle). adaptive caps an edge at 128 segments per face edge; patches cut large "
      "patches into domains, so at small rates it makes the triangles the rate asks "
      "for.\n\n",
      options.views, options.size, options.size, static_cast<unsigned long long>(options.seed));
  std::printf("| shape | faces |");
  for (double rate : options.rates) {
    std::printf(
        " adaptive:%g tris | patches:%g tris | adaptive ms | patches ms | adaptive px | "
        "patches px |",
        rate, rate);
  }
  std::printf("\n|---|---:|");
  for (size_t r = 0; r < options.rates.size(); ++r) std::printf("---:|---:|---:|---:|---:|---:|");
  std::printf("\n");
  double ratioSum = 0, timeRatioSum = 0;
  int ratioCount = 0;
  for (const testing::NamedMesh& shape : shapes) {
    pipeline::CompareJob job;
    job.mesh = shape.mesh;
    subdiv::LimitSurface surface(shape.mesh);
    for (const auto& view :
         testing::randomViews(surface.bounds(), options.views,
                              testing::viewSeed(options.seed, shape.name), options.size)) {
      job.cameras.push_back(view.camera);
    }
    for (double rate : options.rates) {
      for (auto method : {pipeline::Method::Adaptive, pipeline::Method::Patches}) {
        pipeline::MethodParams params;
        params.dicingRate = rate;
        job.methods.push_back({method, params, Shading::Smooth});
      }
    }
    pipeline::JobLimits limits;
    limits.maxCompareRows = job.methods.size() * job.cameras.size();
    std::printf("| %s | %d |", shape.name.c_str(), shape.mesh.faceCount());
    try {
      pipeline::CompareResult result = pipeline::compare(job, limits, context, CancelToken());
      for (size_t m = 0; m < job.methods.size(); m += 2) {
        std::vector<double> tris[2], ms[2], px[2];
        for (const pipeline::CompareRow& row : result.rows) {
          if (row.method != m && row.method != m + 1) continue;
          const int k = static_cast<int>(row.method - m);
          if (row.error) continue;
          tris[k].push_back(static_cast<double>(row.stats.triangles));
          ms[k].push_back(row.timings.approxMs);
          px[k].push_back(row.metrics.silhouette->hausdorffPx);
        }
        auto worst = [](const std::vector<double>& v) {
          return v.empty() ? 0.0 : *std::max_element(v.begin(), v.end());
        };
        std::printf(" %.0f | %.0f | %.1f | %.1f | %.2f (%.2f) | %.2f (%.2f) |", median(tris[0]),
                    median(tris[1]), median(ms[0]), median(ms[1]), median(px[0]), worst(px[0]),
                    median(px[1]), worst(px[1]));
        if (m == 0 && !tris[0].empty() && !tris[1].empty()) {
          ratioSum += median(tris[1]) / median(tris[0]);
          timeRatioSum += median(ms[1]) / std::max(median(ms[0]), 1e-3);
          ++ratioCount;
        }
      }
      std::printf("\n");
    } catch (const std::exception& e) {
      std::printf(" failed: %s |\n", e.what());
    }
    std::fprintf(stderr, "%s done\n", shape.name.c_str());
  }
  if (ratioCount > 0) {
    std::printf(
        "\nAt dicing rate %g: patches make %.2fx the triangles of adaptive and take %.2fx "
        "its time (mean over %d shapes).\n\n",
        options.rates.front(), ratioSum / ratioCount, timeRatioSum / ratioCount, ratioCount);
  }
}

// The rest shape breathing (scaled about its centre by up to 25%) and bending (a sideways
// shift growing with height), frame by frame.
std::vector<Vec3> breathing(const mesh::ControlMesh& rest, const Bounds& bounds, int frame,
                            int frames) {
  const double phase = 2 * std::numbers::pi * frame / frames;
  const Vec3 centre = bounds.center();
  const double height = std::max(bounds.hi.z - bounds.lo.z, 1e-9);
  std::vector<Vec3> out;
  for (const Vec3& p : rest.points) {
    Vec3 q = centre + (p - centre) * (1 + 0.25 * std::sin(phase));
    const double up = (p.z - bounds.lo.z) / height;
    q.x += 0.2 * height * std::sin(phase) * up * up;
    out.push_back(q);
  }
  return out;
}

void printAnimation(const Options& options) {
  std::printf("## Animation: keeping the table and the tessellation against rebuilding them\n\n");
  std::printf(
      "%d frames of a breathing and bending mesh, %d x %d, dicing rate 4, isolation 4 and 6. Per "
      "frame: reused = new control points (stencils) + the first frame's tessellation "
      "re-evaluated at them (what /v1/render's frames do); table kept = new control points + "
      "tessellation anew (params.retessellateFrames); rebuilt = topology, refinement, patch "
      "table, stencils + tessellation. Raster and reference are the same work either way and "
      "left out.\n\n",
      options.frames, options.size, options.size);
  std::printf(
      "| mesh | faces | isolation | reused ms/frame | table kept ms/frame | rebuilt ms/frame | "
      "table kept / reused | rebuilt / reused | of which table ms |\n"
      "|---|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  for (auto [name, rest] : {std::pair{"torus 24x12", testing::torus(24, 12, false)},
                            std::pair{"pawn 588", testing::pawn()},
                            std::pair{"bumpy ball 1536", testing::bumpyBall()}}) {
    const Bounds bounds = subdiv::LimitSurface(rest).bounds();
    for (int isolation : {4, 6}) {
      CameraSpec spec;
      spec.width = spec.height = options.size;
      Camera camera = resolveCamera(spec, bounds);
      patches::TessellationOptions tess;
      tess.dicingRate = 4;
      auto reused = std::chrono::steady_clock::now();
      {
        patches::PatchSet set(rest, isolation, CancelToken());
        patches::TessellationOptions keepAll = tess;
        keepAll.cullHidden = false;
        std::optional<patches::PatchMesh> first;
        for (int f = 0; f < options.frames; ++f) {
          set.setControlPoints(breathing(rest, bounds, f, options.frames));
          if (first) {
            patches::reevaluatePatchMesh(set, *first, CancelToken());
          } else {
            first = patches::tessellatePatches(set, camera, keepAll, CancelToken());
          }
        }
      }
      const double reusedMs = msSince(reused) / options.frames;
      auto kept = std::chrono::steady_clock::now();
      patches::PatchSet set(rest, isolation, CancelToken());
      for (int f = 0; f < options.frames; ++f) {
        set.setControlPoints(breathing(rest, bounds, f, options.frames));
        patches::tessellatePatches(set, camera, tess, CancelToken());
      }
      const double keptMs = msSince(kept) / options.frames;
      double tableMs = 0;
      auto rebuilt = std::chrono::steady_clock::now();
      for (int f = 0; f < options.frames; ++f) {
        mesh::ControlMesh frame = rest;
        frame.points = breathing(rest, bounds, f, options.frames);
        auto table = std::chrono::steady_clock::now();
        patches::PatchSet fresh(frame, isolation, CancelToken());
        tableMs += msSince(table);
        patches::tessellatePatches(fresh, camera, tess, CancelToken());
      }
      const double rebuiltMs = msSince(rebuilt) / options.frames;
      std::printf("| %s | %d | %d | %.2f | %.2f | %.2f | %.2fx | %.2fx | %.2f |\n", name,
                  rest.faceCount(), isolation, reusedMs, keptMs, rebuiltMs, keptMs / reusedMs,
                  rebuiltMs / reusedMs, tableMs / options.frames);
    }
  }
  std::printf("\n");
}

}  // namespace

int main(int argc, char** argv) {
  const Options options = parse(argc, argv);
  std::vector<testing::NamedMesh> shapes = testing::ownShapes();
  for (auto& s : testing::corpusShapes()) shapes.push_back(std::move(s));
  shapes = testing::selectShapes(std::move(shapes), options.shapes);
  raster::Rasterizer rasterizer;
  pipeline::RenderContext context{.rasterizer = &rasterizer};
  std::printf("# The patches method\n\nRenderer: %s; %u hardware threads.\n\n",
              rasterizer.device().renderer.c_str(), std::thread::hardware_concurrency());
  printPatchCounts(shapes);
  printAnimation(options);
  if (options.compare) printComparison(shapes, options, context);
  return 0;
}
