// silhouette_views_bench: the silhouette method from K seeded random views of every shape
// (tests/support/random_views.h), against the exact reference, with uniform levels 1..L drawn
// from the same views for the triangle share. Prints Markdown (bench/silhouette_views_results.md
// keeps the last run):
//   - per shape: the distribution of hausdorffPx over its views (median, 95th percentile,
//     worst and which view), the silhouette's triangles, and its share of the triangles and
//     time of the smallest uniform level that is as accurate from the same view;
//   - per class of shape (closed smooth / semi-sharp / sharp, open): the share of views within
//     1 px, and the distribution;
//   - the worst views, each with the camera JSON that reproduces it through /v1/render.
//
//   silhouette_views_bench [--size 1024] [--views 8] [--seed 1] [--max-level 5] [--worst 20]
//                          [--presubdivide auto|never|once] [--shapes a,b,...] [--dump DIR]
// --dump writes each of the worst views as a /v1/render request body (method silhouette, the
// reference, colour, diff and contours) to DIR/<shape>-view<k>.json, for `limn render`.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "render/oracle/reference_scene.h"
#include "render/pipeline/compare.h"
#include "render/raster/rasterizer.h"
#include "render/subdiv/limit_surface.h"
#include "tests/support/random_views.h"
#include "tests/support/shapes.h"

using namespace limn;
using namespace limn::render;

namespace {

struct Options {
  int size = 1024, views = 8, maxLevel = 5, worst = 20;
  uint64_t seed = 1;
  silhouette::Presubdivide presubdivide = silhouette::Presubdivide::Auto;
  std::vector<std::string> shapes;
  std::string dump;
};

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i + 1 < argc; i += 2) {
    std::string flag = argv[i], value = argv[i + 1];
    if (flag == "--size") o.size = std::stoi(value);
    if (flag == "--views") o.views = std::stoi(value);
    if (flag == "--seed") o.seed = std::stoull(value);
    if (flag == "--max-level") o.maxLevel = std::stoi(value);
    if (flag == "--worst") o.worst = std::stoi(value);
    if (flag == "--dump") o.dump = value;
    if (flag == "--presubdivide") {
      o.presubdivide = value == "never"  ? silhouette::Presubdivide::Never
                       : value == "once" ? silhouette::Presubdivide::Once
                                         : silhouette::Presubdivide::Auto;
    }
    if (flag == "--shapes") {
      std::stringstream in(value);
      for (std::string s; std::getline(in, s, ',');) o.shapes.push_back(s);
    }
  }
  return o;
}

// One (shape, view) pair.
struct ViewResult {
  const testing::NamedMesh* mesh = nullptr;
  std::string shape, shapeClass;
  int view = 0;
  std::string camera;
  std::optional<std::string> error;
  double px = 0, outlinePx = 0, psnr = 0;
  size_t triangles = 0;
  double ms = 0;
  int uniformLevel = 0;  // smallest as accurate, 0: none up to maxLevel
  size_t uniformTriangles = 0;
  double uniformMs = 0;
};

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  size_t i = static_cast<size_t>(q * static_cast<double>(v.size() - 1) + 0.5);
  return v[std::min(i, v.size() - 1)];
}

double rowMs(const pipeline::CompareRow& row) {
  return row.timings.approxMs + row.timings.rasterMs;
}

std::vector<ViewResult> measureShape(const testing::NamedMesh& shape, const Options& options,
                                     pipeline::RenderContext& context) {
  pipeline::CompareJob job;
  job.mesh = shape.mesh;
  subdiv::LimitSurface surface(shape.mesh);
  std::vector<testing::RandomView> views = testing::randomViews(
      surface.bounds(), options.views, testing::viewSeed(options.seed, shape.name), options.size);
  for (const auto& view : views) job.cameras.push_back(view.camera);
  pipeline::MethodParams silhouetteParams;
  silhouetteParams.presubdivide = options.presubdivide;
  job.methods.push_back({pipeline::Method::Silhouette, silhouetteParams, Shading::Smooth});
  for (int level = 1; level <= options.maxLevel; ++level) {
    pipeline::MethodParams params;
    params.level = level;
    job.methods.push_back({pipeline::Method::Uniform, params, Shading::Smooth});
  }
  pipeline::JobLimits limits;
  limits.maxCompareRows = job.methods.size() * job.cameras.size();
  pipeline::CompareResult result = pipeline::compare(job, limits, context, CancelToken());

  const std::string kind = testing::shapeClass(shape.mesh);
  std::vector<ViewResult> out;
  const size_t methods = job.methods.size();
  for (size_t c = 0; c < job.cameras.size(); ++c) {
    ViewResult v;
    v.mesh = &shape;
    v.shape = shape.name;
    v.shapeClass = kind;
    v.view = static_cast<int>(c);
    v.camera = testing::describeCamera(job.cameras[c]);
    const pipeline::CompareRow& sil = result.rows[c * methods];
    if (sil.error) {
      v.error = sil.error->message;
      out.push_back(v);
      continue;
    }
    v.px = sil.metrics.silhouette->hausdorffPx;
    v.outlinePx = sil.metrics.silhouette->outlineHausdorffPx.value_or(-1);
    v.psnr = sil.metrics.image ? sil.metrics.image->psnr : 0;
    v.triangles = sil.stats.triangles;
    v.ms = rowMs(sil);
    for (size_t m = 1; m < methods; ++m) {
      const pipeline::CompareRow& row = result.rows[c * methods + m];
      if (row.error || row.metrics.silhouette->hausdorffPx > v.px + 1e-9) continue;
      v.uniformLevel = static_cast<int>(m);
      v.uniformTriangles = row.stats.triangles;
      v.uniformMs = rowMs(row);
      break;
    }
    out.push_back(v);
  }
  return out;
}

void printShapeTable(const std::vector<ViewResult>& all) {
  std::printf(
      "| shape | class | views | median px | p95 px | worst px (view) | within 1 px | median "
      "tris | median share of uniform tris | median time vs uniform |\n"
      "|---|---|---:|---:|---:|---|---:|---:|---:|---:|\n");
  std::map<std::string, std::vector<const ViewResult*>> byShape;
  std::vector<std::string> order;
  for (const ViewResult& v : all) {
    if (!byShape.count(v.shape)) order.push_back(v.shape);
    byShape[v.shape].push_back(&v);
  }
  for (const std::string& name : order) {
    const auto& views = byShape[name];
    std::vector<double> px, tris, share, time;
    const ViewResult* worst = nullptr;
    int within = 0, failed = 0;
    for (const ViewResult* v : views) {
      if (v->error) {
        ++failed;
        continue;
      }
      px.push_back(v->px);
      tris.push_back(static_cast<double>(v->triangles));
      within += v->px <= 1.0;
      if (!worst || v->px > worst->px) worst = v;
      if (v->uniformLevel > 0) {
        share.push_back(static_cast<double>(v->triangles) /
                        static_cast<double>(v->uniformTriangles));
        time.push_back(v->ms / v->uniformMs);
      }
    }
    std::string shareText =
        share.empty() ? "none as accurate"
                      : std::to_string(static_cast<int>(100 * quantile(share, 0.5) + 0.5)) + "%";
    std::string timeText =
        time.empty() ? "-" : std::to_string(quantile(time, 0.5)).substr(0, 4) + "x";
    std::printf(
        "| %s | %s | %zu%s | %.3f | %.3f | %.3f (%d) | %d/%zu | %.0f | %s (%zu views) | %s |\n",
        name.c_str(), views[0]->shapeClass.c_str(), views.size(),
        failed ? (" (" + std::to_string(failed) + " failed)").c_str() : "", quantile(px, 0.5),
        quantile(px, 0.95), worst ? worst->px : -1, worst ? worst->view : -1, within, px.size(),
        quantile(tris, 0.5), shareText.c_str(), share.size(), timeText.c_str());
  }
  std::printf("\n");
}

void printClassTable(const std::vector<ViewResult>& all) {
  std::printf(
      "| class | pairs | within 1 px | over 3 px | failed | median px | p95 px | worst px |\n"
      "|---|---:|---:|---:|---:|---:|---:|---:|\n");
  std::map<std::string, std::vector<const ViewResult*>> byClass;
  for (const ViewResult& v : all) {
    byClass[v.shapeClass].push_back(&v);
    byClass[testing::isClosedClass(v.shapeClass) ? "all closed" : "all open"].push_back(&v);
    byClass["all"].push_back(&v);
  }
  for (const auto& [name, views] : byClass) {
    std::vector<double> px;
    int within = 0, over3 = 0, failed = 0;
    for (const ViewResult* v : views) {
      if (v->error) {
        ++failed;
        continue;
      }
      px.push_back(v->px);
      within += v->px <= 1.0;
      over3 += v->px > 3.0;
    }
    std::printf("| %s | %zu | %.1f%% | %d | %d | %.3f | %.3f | %.3f |\n", name.c_str(),
                views.size(), 100.0 * within / static_cast<double>(views.size()), over3, failed,
                quantile(px, 0.5), quantile(px, 0.95), px.empty() ? 0 : quantile(px, 1.0));
  }
  std::printf("\n");
}

void dumpRequest(const ViewResult& v, const std::string& dir) {
  std::filesystem::create_directories(dir);
  std::ofstream out(dir + "/" + v.shape + "-view" + std::to_string(v.view) + ".json");
  out << "{\"mesh\": " << testing::requestMeshJson(v.mesh->mesh) << ",\n \"camera\": " << v.camera
      << ",\n \"method\": \"silhouette\", \"reference\": true,"
         " \"outputs\": [\"color\", \"diff\", \"contours\"]}\n";
}

void printWorst(std::vector<ViewResult> all, int count, const std::string& dump) {
  std::sort(all.begin(), all.end(), [](const ViewResult& a, const ViewResult& b) {
    if (a.error.has_value() != b.error.has_value()) return a.error.has_value();
    return a.px > b.px;
  });
  std::printf(
      "| shape | view | hausdorffPx | outline px | PSNR | camera "
      "|\n|---|---:|---:|---:|---:|---|\n");
  for (int i = 0; i < count && i < static_cast<int>(all.size()); ++i) {
    const ViewResult& v = all[i];
    if (!dump.empty()) dumpRequest(v, dump);
    if (v.error) {
      std::printf("| %s | %d | failed: %s | - | - | `%s` |\n", v.shape.c_str(), v.view,
                  v.error->c_str(), v.camera.c_str());
    } else {
      std::printf("| %s | %d | %.3f | %.3f | %.1f | `%s` |\n", v.shape.c_str(), v.view, v.px,
                  v.outlinePx, v.psnr, v.camera.c_str());
    }
  }
  std::printf("\n");
}

}  // namespace

int main(int argc, char** argv) {
  const Options options = parse(argc, argv);
  raster::Rasterizer rasterizer;
  pipeline::RenderContext context{.rasterizer = &rasterizer};
  std::vector<testing::NamedMesh> shapes = testing::ownShapes();
  for (auto& s : testing::corpusShapes()) shapes.push_back(std::move(s));
  shapes = testing::selectShapes(std::move(shapes), options.shapes);

  std::printf("# The silhouette method from random views, %d x %d, S = 4\n\n", options.size,
              options.size);
  std::printf(
      "Renderer: %s. %d views per shape, seed %llu (eye 1.5-4 bounding radii from the centre, "
      "random up, fov 20-60 degrees, one in four orthographic). Share: the silhouette's "
      "triangles over those of the smallest uniform level (1-%d) with hausdorffPx at most the "
      "silhouette's from the same view; time: approximation + raster, the same ratio.\n\n",
      rasterizer.device().renderer.c_str(), options.views,
      static_cast<unsigned long long>(options.seed), options.maxLevel);
  std::vector<ViewResult> all;
  for (const testing::NamedMesh& shape : shapes) {
    try {
      std::vector<ViewResult> rows = measureShape(shape, options, context);
      all.insert(all.end(), rows.begin(), rows.end());
    } catch (const std::exception& e) {
      std::fprintf(stderr, "%s: %s\n", shape.name.c_str(), e.what());
    }
    std::fprintf(stderr, "%s done\n", shape.name.c_str());
  }
  std::printf("## By class\n\n");
  printClassTable(all);
  std::printf("## By shape\n\n");
  printShapeTable(all);
  std::printf("## The worst views\n\n");
  printWorst(all, options.worst, options.dump);
  return 0;
}
