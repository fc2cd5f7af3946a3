// silhouette_bench: the silhouette method against coarse, uniform levels 1-5 and adaptive
// (dicing rate 1) on the corpus and the project's own meshes at 1024^2, oblique camera.
// For each shape and method: triangles drawn, silhouette Hausdorff distance to the exact
// reference (S = 4) and the time to answer (approximation + colour raster, warm, best of
// --repeat). Then a summary: the smallest uniform level that reaches the error of "exact", how
// many of its triangles "exact" draws, and how their times compare. Prints Markdown
// (bench/silhouette_results.md keeps the last run).
//
//   silhouette_bench [--size 1024] [--repeat 3] [--shapes a,b,...]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "formats/obj_reader.h"
#include "render/metrics/metrics.h"
#include "render/oracle/reference.h"
#include "render/raster/rasterizer.h"
#include "render/silhouette/presubdivide.h"
#include "render/silhouette/silhouette_mesh.h"
#include "render/tessellate/tessellate.h"
#include "tests/unit/test_meshes.h"

namespace fs = std::filesystem;
using namespace limn;
using namespace limn::render;

namespace {

struct Shape {
  std::string name;
  mesh::ControlMesh mesh;
};

std::vector<Shape> loadShapes(const std::vector<std::string>& only) {
  std::vector<Shape> shapes = {
      {"own_cube", testing::cube()},
      {"own_icosahedron_loop", testing::icosahedron()},
      {"own_torus_12x8_creased", testing::torus(12, 8, true)},
      {"own_torus_40x25", testing::torus(40, 25, false)},
  };
  fs::path corpus = fs::path(LIMN_SOURCE_DIR) / ".." / "shared" / "corpus" / "osd-shapes";
  std::vector<fs::path> files;
  if (fs::exists(corpus)) {
    for (const auto& entry : fs::directory_iterator(corpus)) {
      if (entry.path().extension() == ".obj") files.push_back(entry.path());
    }
  }
  std::sort(files.begin(), files.end());
  for (const fs::path& path : files) {
    std::string name = path.stem().string();
    if (name.rfind("bilinear_", 0) == 0) continue;
    std::ifstream file(path);
    std::stringstream text;
    text << file.rdbuf();
    auto scheme = name.rfind("loop_", 0) == 0 ? mesh::Scheme::Loop : mesh::Scheme::CatmullClark;
    shapes.push_back({name, formats::readObj(text.str(), scheme, {}).mesh});
  }
  if (!only.empty()) {
    std::erase_if(shapes, [&](const Shape& s) {
      return std::find(only.begin(), only.end(), s.name) == only.end();
    });
  }
  return shapes;
}

// "closed smooth", "closed semi-sharp" or "open/sharp": the classes the acceptance criteria
// name (a closed mesh has no boundary edge; sharp means an infinitely sharp crease or corner).
std::string classify(const subdiv::LimitSurface& surface) {
  const auto& base = surface.baseLevel();
  for (int e = 0; e < base.GetNumEdges(); ++e) {
    if (base.IsEdgeBoundary(e) || base.IsEdgeNonManifold(e)) return "open/sharp";
  }
  if (!surface.mesh().holes.empty()) return "open/sharp";
  bool semi = false;
  for (const auto& c : surface.mesh().creases) {
    if (c.sharpness >= mesh::kInfiniteSharpness) return "open/sharp";
    if (c.sharpness > 0) semi = true;
  }
  for (const auto& c : surface.mesh().corners) {
    if (c.sharpness >= mesh::kInfiniteSharpness) return "open/sharp";
    if (c.sharpness > 0) semi = true;
  }
  return semi ? "closed semi-sharp" : "closed smooth";
}

Camera obliqueCamera(const Bounds& bounds, int size) {
  Vec3 dir = normalize(Vec3{0.45, 0.55, 0.70});
  double radius = bounds.diagonal() / 2;
  double distance = radius / std::sin(35.0 * M_PI / 360.0) * 1.05;
  CameraSpec spec;
  spec.target = bounds.center();
  spec.eye = bounds.center() + dir * distance;
  spec.width = spec.height = size;
  return resolveCamera(spec, bounds);
}

double msSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

struct Row {
  std::string method;
  size_t triangles = 0;
  double hausdorffPx = 0, meanPx = 0, ms = 0;
};

}  // namespace

int main(int argc, char** argv) {
  int size = 1024, repeat = 3;
  std::vector<std::string> only;
  for (int i = 1; i + 1 < argc; i += 2) {
    std::string flag = argv[i];
    if (flag == "--size") size = std::stoi(argv[i + 1]);
    if (flag == "--repeat") repeat = std::stoi(argv[i + 1]);
    if (flag == "--shapes") {
      std::stringstream in(argv[i + 1]);
      for (std::string s; std::getline(in, s, ',');) only.push_back(s);
    }
  }
  const int S = 4;
  raster::Rasterizer rasterizer;
  std::printf("# Silhouette method vs. uniform and adaptive, %d x %d, S = %d\n\n", size, size, S);
  std::printf("Renderer: %s. Time = approximation + colour raster, warm, best of %d.\n\n",
              rasterizer.device().renderer.c_str(), repeat);

  struct Summary {
    std::string shape, kind;
    double exactPx = 0, pnPx = 0;
    size_t exactTris = 0;
    double exactMs = 0;
    std::string uniformMatch;
    size_t uniformTris = 0;
    double uniformMs = 0;
  };
  std::vector<Summary> summaries;

  for (const Shape& shape : loadShapes(only)) {
    std::optional<subdiv::LimitSurface> surface;
    try {
      surface.emplace(shape.mesh);
    } catch (const std::exception& e) {
      std::printf("## %s\n\nskipped: %s\n\n", shape.name.c_str(), e.what());
      continue;
    }
    std::unique_ptr<subdiv::LimitSurface> refined;
    const bool presub = !silhouette::presubdivisionReason(shape.mesh).empty();
    try {
      if (presub) {
        refined = std::make_unique<subdiv::LimitSurface>(silhouette::refineOnce(shape.mesh));
      }
    } catch (const std::exception& e) {
      std::printf("## %s\n\nskipped: the pre-subdivided mesh is refused: %s\n\n",
                  shape.name.c_str(), e.what());
      continue;
    }
    const Camera camera = obliqueCamera(surface->bounds(), size);
    PassSelection refPasses{.mask = true, .supersample = S};
    oracle::ReferenceResult reference =
        oracle::renderReference(*surface, camera, refPasses, CancelToken());
    const subdiv::LimitSurface& drawn = refined ? *refined : *surface;

    using Build = std::function<tessellate::TriangleMesh()>;
    std::vector<std::pair<std::string, Build>> methods;
    methods.push_back({"coarse", [&] { return tessellate::tessellateCoarse(*surface); }});
    for (int level = 1; level <= 5; ++level) {
      methods.push_back({"uniform L" + std::to_string(level), [&, level] {
                           return tessellate::tessellateUniform(*surface, level, 8'000'000);
                         }});
    }
    methods.push_back({"adaptive dr1", [&] {
                         tessellate::AdaptiveOptions o;
                         return tessellate::tessellateAdaptive(*surface, camera, o, CancelToken());
                       }});
    for (auto mode : {silhouette::CurveMode::PN, silhouette::CurveMode::Exact}) {
      std::string label = mode == silhouette::CurveMode::PN ? "silhouette pn" : "silhouette exact";
      methods.push_back({label, [&, mode] {
                           // The pre-subdivision is part of the method's cost.
                           std::unique_ptr<subdiv::LimitSurface> fresh;
                           if (presub) {
                             fresh = std::make_unique<subdiv::LimitSurface>(
                                 silhouette::refineOnce(shape.mesh));
                           }
                           silhouette::SilhouetteOptions o;
                           o.curves.mode = mode;
                           return silhouette::buildSilhouetteMesh(fresh ? *fresh : drawn, camera, o,
                                                                  CancelToken())
                               .mesh;
                         }});
    }

    std::vector<Row> rows;
    for (auto& [label, build] : methods) {
      Row row{label};
      try {
        double best = 1e300;
        tessellate::TriangleMesh mesh;
        for (int r = 0; r <= repeat; ++r) {  // the first run warms up
          auto start = std::chrono::steady_clock::now();
          mesh = build();
          rasterizer.render(mesh, camera, PassSelection{.color = true}, Shading::Smooth);
          if (r > 0) best = std::min(best, msSince(start));
        }
        row.ms = best;
        row.triangles = mesh.triangleCount();
        ImageSet images = rasterizer.render(
            mesh, camera, PassSelection{.mask = true, .supersample = S}, Shading::Smooth);
        metrics::SilhouetteMetrics m = metrics::compareSilhouettes(
            images.supersampledMask, reference.images.supersampledMask, S);
        row.hausdorffPx = m.hausdorffPx;
        row.meanPx = m.meanPx;
      } catch (const std::exception& e) {
        row.hausdorffPx = -1;
        std::fprintf(stderr, "%s %s: %s\n", shape.name.c_str(), label.c_str(), e.what());
      }
      rows.push_back(row);
    }

    Summary summary;
    summary.shape = shape.name;
    summary.kind = classify(*surface);
    std::printf("## %s (%s, %d faces%s)\n\n", shape.name.c_str(), summary.kind.c_str(),
                shape.mesh.faceCount(), presub ? ", silhouette pre-subdivided" : "");
    std::printf("| method | triangles | hausdorffPx | meanPx | ms |\n|---|---:|---:|---:|---:|\n");
    for (const Row& row : rows) {
      if (row.hausdorffPx < 0) {
        std::printf("| %s | - | failed | - | - |\n", row.method.c_str());
        continue;
      }
      std::printf("| %s | %zu | %.3f | %.3f | %.1f |\n", row.method.c_str(), row.triangles,
                  row.hausdorffPx, row.meanPx, row.ms);
      if (row.method == "silhouette exact") {
        summary.exactPx = row.hausdorffPx;
        summary.exactTris = row.triangles;
        summary.exactMs = row.ms;
      }
      if (row.method == "silhouette pn") summary.pnPx = row.hausdorffPx;
    }
    for (const Row& row : rows) {
      if (row.method.rfind("uniform", 0) == 0 && row.hausdorffPx >= 0 &&
          row.hausdorffPx <= summary.exactPx && summary.uniformMatch.empty()) {
        summary.uniformMatch = row.method;
        summary.uniformTris = row.triangles;
        summary.uniformMs = row.ms;
      }
    }
    std::printf("\n");
    std::fflush(stdout);
    summaries.push_back(summary);
  }

  std::printf("## Summary\n\n");
  std::printf(
      "| shape | class | exact px | pn px | exact tris | uniform reaching it | its tris | "
      "tris ratio | exact ms | uniform ms |\n");
  std::printf("|---|---|---:|---:|---:|---|---:|---:|---:|---:|\n");
  for (const Summary& s : summaries) {
    if (s.uniformMatch.empty()) {
      std::printf("| %s | %s | %.3f | %.3f | %zu | none up to L5 | - | - | %.1f | - |\n",
                  s.shape.c_str(), s.kind.c_str(), s.exactPx, s.pnPx, s.exactTris, s.exactMs);
    } else {
      std::printf("| %s | %s | %.3f | %.3f | %zu | %s | %zu | %.1f%% | %.1f | %.1f |\n",
                  s.shape.c_str(), s.kind.c_str(), s.exactPx, s.pnPx, s.exactTris,
                  s.uniformMatch.c_str(), s.uniformTris,
                  100.0 * static_cast<double>(s.exactTris) / static_cast<double>(s.uniformTris),
                  s.exactMs, s.uniformMs);
    }
  }
  return 0;
}
