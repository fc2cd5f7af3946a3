// edge_table_bench: the edge tables (render/silhouette/edge_tables.h) against Bfr
// (LimitSurface::evaluate) along every eligible edge of the project's shapes and the corpus's
// Catmull-Clark and Loop shapes, plus split prisms and bipyramids with an end of every valence
// 3..16 (tests/unit/test_meshes.h), at the tables' 129 steps. Prints Markdown
// (bench/edge_table_results.md keeps a run):
//   - per scheme and valence of the edge's extraordinary end ("regular": both ends regular):
//     eligible edges, the largest position error over the bounding-box diagonal and normal
//     angle (against Bfr in each of the edge's two faces), and the time per evaluated point
//     (position + normal) of Bfr and of the tables, with the tables' gather of support points
//     amortised over the 129 points of an edge and over the 8 points the contour search
//     evaluates on a sampled edge with one crossing (3 samples, 5 bisections);
//   - per shape: the share of edges that is eligible;
//   - the contour search itself (render/silhouette/contour_search.h) from `--views` random views
//     of each shape (not the prisms and bipyramids), with the tables (SearchOptions::edgeTables)
//     and without: its time, and how far the edge points it finds move (they should not, beyond
//     rounding).
// Times are the best of `--repeat` runs, Bfr and tables alternating in the same run.
//
//   edge_table_bench [--repeat 5] [--views 4] [--seed 1] [--shapes a,b,...]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "bench/bench_common.h"
#include "render/silhouette/contour_search.h"
#include "render/silhouette/edge_tables.h"
#include "render/subdiv/limit_surface.h"
#include "tests/support/random_views.h"
#include "tests/support/shapes.h"
#include "tests/unit/test_meshes.h"

using namespace limn;
using namespace limn::render;
using silhouette::EdgeCurve;
using silhouette::EdgeSample;
using silhouette::EdgeSupport;
using silhouette::kEdgeTableSteps;

namespace Far = OpenSubdiv::Far;

namespace {

constexpr int kPointsPerEdge = kEdgeTableSteps + 1;
// Points the contour search evaluates on a sampled edge with one crossing: g at t = 1/4, 1/2,
// 3/4, then five bisections.
constexpr int kSearchPointsPerEdge = 8;
// Each timed job is repeated until it has run this long, so small classes time reliably.
constexpr double kMinJobMs = 5.0;
constexpr double kMinSearchMs = 20.0;

struct Options {
  int repeat = 5, views = 4;
  uint64_t seed = 1;
  std::vector<std::string> shapes;
};

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i + 1 < argc; i += 2) {
    std::string flag = argv[i], value = argv[i + 1];
    if (flag == "--repeat") o.repeat = std::max(1, std::stoi(value));
    if (flag == "--views") o.views = std::max(1, std::stoi(value));
    if (flag == "--seed") o.seed = std::stoull(value);
    if (flag == "--shapes") o.shapes = bench::splitList(value);
  }
  return o;
}

// The class of an eligible edge: scheme and valence of its extraordinary end.
struct ClassKey {
  mesh::Scheme scheme;
  int valence;
  bool operator<(const ClassKey& o) const {
    return std::tie(scheme, valence) < std::tie(o.scheme, o.valence);
  }
};

struct ClassStats {
  std::map<std::string, bool> shapes;
  size_t edges = 0;
  double maxPositionError = 0, maxNormalAngle = 0;
  // Sums over shapes of each shape's best time (ns), and what they timed.
  double bfrNs = 0, samplesNs = 0, gatherNs = 0;
  size_t timedPoints = 0, timedEdges = 0;
};

struct Edge {
  int edge, face;  // the face Bfr is timed in: the edge's first, as the contour search does
  Vec2 from, to;   // the edge's ends in that face's (u, v)
  EdgeSupport support;
};

double angleBetween(const Vec3& a, const Vec3& b) {
  return std::atan2(length(cross(a, b)), dot(a, b));
}

Vec2 along(const Edge& e, int k) {
  const double t = static_cast<double>(k) / kEdgeTableSteps;
  return {e.from.x + (e.to.x - e.from.x) * t, e.from.y + (e.to.y - e.from.y) * t};
}

Vec2 endInFace(const subdiv::LimitSurface& surface, int face, int vertex) {
  Far::ConstIndexArray corners = surface.baseLevel().GetFaceVertices(face);
  const int local =
      static_cast<int>(std::find(corners.begin(), corners.end(), vertex) - corners.begin());
  return surface.cornerUV(face, local);
}

// Runs `job` until `minMs` has passed; nanoseconds per run.
template <class Job>
double nsPerRun(Job&& job, double minMs = kMinJobMs) {
  using Clock = std::chrono::steady_clock;
  int runs = 0;
  const auto start = Clock::now();
  double elapsed = 0;
  do {
    job();
    ++runs;
    elapsed = std::chrono::duration<double, std::nano>(Clock::now() - start).count();
  } while (elapsed < minMs * 1e6);
  return elapsed / runs;
}

volatile double sink = 0;  // keeps the evaluations from being optimised away

void measureAccuracy(const subdiv::LimitSurface& surface, const mesh::ControlMesh& m,
                     const std::vector<Edge>& edges, ClassStats& stats) {
  const Bounds box = surface.bounds();
  const double diagonal = length(box.hi - box.lo);
  for (const Edge& e : edges) {
    EdgeCurve curve(e.support, m.points, m.scheme);
    for (int face : surface.baseLevel().GetEdgeFaces(e.edge)) {
      Far::ConstIndexArray ends = surface.baseLevel().GetEdgeVertices(e.edge);
      Edge inFace = e;
      inFace.from = endInFace(surface, face, ends[0]);
      inFace.to = endInFace(surface, face, ends[1]);
      for (int k = 0; k < kPointsPerEdge; ++k) {
        const Vec2 uv = along(inFace, k);
        subdiv::LimitSample bfr = surface.evaluate(face, uv.x, uv.y);
        EdgeSample table = curve.sample(k);
        stats.maxPositionError =
            std::max(stats.maxPositionError, length(table.position - bfr.position) / diagonal);
        stats.maxNormalAngle =
            std::max(stats.maxNormalAngle, angleBetween(table.normal, bfr.normal));
      }
    }
  }
}

void measureSpeed(const subdiv::LimitSurface& surface, const mesh::ControlMesh& m,
                  const std::vector<Edge>& edges, int repeat, ClassStats& stats) {
  const Far::TopologyLevel& level = surface.baseLevel();
  std::vector<EdgeCurve> curves;
  for (const Edge& e : edges) curves.emplace_back(e.support, m.points, m.scheme);
  double bestBfr = 1e300, bestSamples = 1e300, bestGather = 1e300;
  for (int r = 0; r < repeat; ++r) {
    bestBfr = std::min(bestBfr, nsPerRun([&] {
                         double sum = 0;
                         for (const Edge& e : edges) {
                           for (int k = 0; k < kPointsPerEdge; ++k) {
                             const Vec2 uv = along(e, k);
                             subdiv::LimitSample s = surface.evaluate(e.face, uv.x, uv.y);
                             sum += s.position.x + s.normal.x;
                           }
                         }
                         sink = sum;
                       }));
    bestSamples = std::min(bestSamples, nsPerRun([&] {
                             double sum = 0;
                             for (const EdgeCurve& curve : curves) {
                               for (int k = 0; k < kPointsPerEdge; ++k) {
                                 EdgeSample s = curve.sample(k);
                                 sum += s.position.x + s.normal.x;
                               }
                             }
                             sink = sum;
                           }));
    bestGather = std::min(bestGather, nsPerRun([&] {
                            double sum = 0;
                            for (const Edge& e : edges) {
                              std::optional<EdgeSupport> support =
                                  silhouette::gatherEdgeSupport(level, m.scheme, e.edge);
                              EdgeCurve curve(*support, m.points, m.scheme);
                              sum += support->count;
                            }
                            sink = sum;
                          }));
  }
  stats.bfrNs += bestBfr;
  stats.samplesNs += bestSamples;
  stats.gatherNs += bestGather;
  stats.timedPoints += edges.size() * kPointsPerEdge;
  stats.timedEdges += edges.size();
}

struct ShapeShare {
  std::string name;
  mesh::Scheme scheme;
  int edges = 0, eligible = 0;
};

// The contour search on one shape, summed over its views.
struct SearchComparison {
  std::string name;
  size_t sampled = 0, onTables = 0, points = 0;
  bool samePointCounts = true;
  double maxParameterShift = 0, maxPositionShift = 0;  // position over the diagonal
  double bfrMs = 0, tablesMs = 0;                      // sums of each view's best time
};

SearchComparison compareSearch(const testing::NamedMesh& shape, const Options& options) {
  subdiv::LimitSurface surface(shape.mesh);
  const silhouette::FaceDomains domains(surface);
  const Bounds box = surface.bounds();
  const double diagonal = length(box.hi - box.lo);
  SearchComparison out{shape.name};
  silhouette::SearchOptions onBfr, onTables;
  onBfr.edgeTables = false;
  onTables.edgeTables = true;
  for (const testing::RandomView& view :
       testing::randomViews(box, options.views, testing::viewSeed(options.seed, shape.name), 512)) {
    const Camera camera = resolveCamera(view.camera, box);
    auto search = [&](const silhouette::SearchOptions& o) {
      return silhouette::searchContour(domains, camera, o, CancelToken());
    };
    double bestBfr = 1e300, bestTables = 1e300;
    for (int r = 0; r < options.repeat; ++r) {
      bestBfr = std::min(bestBfr,
                         nsPerRun([&] { sink = search(onBfr).stats.contourPoints; }, kMinSearchMs));
      bestTables = std::min(
          bestTables, nsPerRun([&] { sink = search(onTables).stats.contourPoints; }, kMinSearchMs));
    }
    out.bfrMs += bestBfr * 1e-6;
    out.tablesMs += bestTables * 1e-6;
    silhouette::ContourSearch a = search(onBfr), b = search(onTables);
    out.sampled += b.stats.edgesSampled;
    out.onTables += b.stats.edgesOnTables;
    out.points += b.stats.contourPoints;
    for (size_t e = 0; e < a.edgePoints.size(); ++e) {
      if (a.edgePoints[e].size() != b.edgePoints[e].size()) {
        out.samePointCounts = false;
        continue;
      }
      for (size_t i = 0; i < a.edgePoints[e].size(); ++i) {
        const silhouette::EdgePoint &p = a.edgePoints[e][i], &q = b.edgePoints[e][i];
        out.samePointCounts = out.samePointCounts && p.sides == q.sides;
        out.maxParameterShift = std::max(out.maxParameterShift, std::fabs(p.t - q.t));
        out.maxPositionShift =
            std::max(out.maxPositionShift, length(p.position - q.position) / diagonal);
      }
    }
  }
  return out;
}

void printSearchTable(const std::vector<SearchComparison>& rows, int views) {
  std::printf(
      "| shape | views | sampled edges | on tables | edge points | same points | max t shift | max "
      "position shift / diagonal | search ms, Bfr | search ms, tables | Bfr / tables |\n"
      "|---|---:|---:|---:|---:|---|---:|---:|---:|---:|---:|\n");
  double bfr = 0, tables = 0;
  for (const SearchComparison& r : rows) {
    std::printf("| %s | %d | %zu | %zu | %zu | %s | %.1e | %.1e | %.3f | %.3f | %.2fx |\n",
                r.name.c_str(), views, r.sampled, r.onTables, r.points,
                r.samePointCounts ? "yes" : "NO", r.maxParameterShift, r.maxPositionShift, r.bfrMs,
                r.tablesMs, r.bfrMs / r.tablesMs);
    bfr += r.bfrMs;
    tables += r.tablesMs;
  }
  std::printf("| all | | | | | | | | %.3f | %.3f | %.2fx |\n\n", bfr, tables, bfr / tables);
}

ShapeShare measureShape(const testing::NamedMesh& shape, const Options& options,
                        std::map<ClassKey, ClassStats>& classes) {
  const mesh::ControlMesh& m = shape.mesh;
  subdiv::LimitSurface surface(m);
  const Far::TopologyLevel& level = surface.baseLevel();
  ShapeShare share{shape.name, m.scheme, level.GetNumEdges(), 0};
  std::map<int, std::vector<Edge>> byValence;
  for (int e = 0; e < level.GetNumEdges(); ++e) {
    std::optional<EdgeSupport> support = silhouette::gatherEdgeSupport(level, m.scheme, e);
    if (!support) continue;
    ++share.eligible;
    const int face = level.GetEdgeFaces(e)[0];
    Far::ConstIndexArray ends = level.GetEdgeVertices(e);
    byValence[support->valence].push_back(
        {e, face, endInFace(surface, face, ends[0]), endInFace(surface, face, ends[1]), *support});
  }
  for (const auto& [valence, edges] : byValence) {
    ClassStats& stats = classes[{m.scheme, valence}];
    stats.shapes[shape.name] = true;
    stats.edges += edges.size();
    measureAccuracy(surface, m, edges, stats);
    measureSpeed(surface, m, edges, options.repeat, stats);
  }
  return share;
}

void printClassTable(const std::map<ClassKey, ClassStats>& classes) {
  std::printf(
      "| scheme | valence | eligible edges | shapes | max position error / diagonal | max normal "
      "angle (rad) | Bfr ns/point | tables ns/point (gather over 129) | gather ns/edge | tables "
      "ns/point (gather over 8) | Bfr / tables (129) | Bfr / tables (8) |\n"
      "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  for (const auto& [key, s] : classes) {
    const double bfr = s.bfrNs / s.timedPoints;
    const double gather = s.gatherNs / s.timedEdges;
    const double samples = s.samplesNs / s.timedPoints;
    const double over129 = samples + gather / kPointsPerEdge;
    const double over8 = samples + gather / kSearchPointsPerEdge;
    const bool regular = key.valence == silhouette::EdgeTables::regularValence(key.scheme);
    std::printf(
        "| %s | %s | %zu | %zu | %.1e | %.1e | %.0f | %.0f | %.0f | %.0f | %.1fx | %.1fx |\n",
        mesh::schemeName(key.scheme), regular ? "regular" : std::to_string(key.valence).c_str(),
        s.edges, s.shapes.size(), s.maxPositionError, s.maxNormalAngle, bfr, over129, gather, over8,
        bfr / over129, bfr / over8);
  }
  std::printf("\n");
}

// Per scheme: all eligible edges together, times weighted by the points timed.
void printSchemeTable(const std::map<ClassKey, ClassStats>& classes,
                      const std::vector<ShapeShare>& shares) {
  std::printf(
      "| scheme | shapes | edges | eligible | share | max position error / diagonal | max normal "
      "angle (rad) | Bfr ns/point | tables ns/point (gather over 129) | tables ns/point (gather "
      "over 8) | Bfr / tables (129) | Bfr / tables (8) |\n"
      "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  for (mesh::Scheme scheme : {mesh::Scheme::CatmullClark, mesh::Scheme::Loop}) {
    int shapes = 0;
    long edges = 0, eligible = 0;
    for (const ShapeShare& s : shares) {
      if (s.scheme != scheme) continue;
      ++shapes;
      edges += s.edges;
      eligible += s.eligible;
    }
    ClassStats all;
    for (const auto& [key, s] : classes) {
      if (key.scheme != scheme) continue;
      all.maxPositionError = std::max(all.maxPositionError, s.maxPositionError);
      all.maxNormalAngle = std::max(all.maxNormalAngle, s.maxNormalAngle);
      all.bfrNs += s.bfrNs;
      all.samplesNs += s.samplesNs;
      all.gatherNs += s.gatherNs;
      all.timedPoints += s.timedPoints;
      all.timedEdges += s.timedEdges;
    }
    if (all.timedPoints == 0) continue;
    const double bfr = all.bfrNs / all.timedPoints;
    const double samples = all.samplesNs / all.timedPoints;
    const double gather = all.gatherNs / all.timedEdges;
    const double over129 = samples + gather / kPointsPerEdge;
    const double over8 = samples + gather / kSearchPointsPerEdge;
    std::printf(
        "| %s | %d | %ld | %ld | %.1f%% | %.1e | %.1e | %.0f | %.0f | %.0f | %.1fx | %.1fx |\n",
        mesh::schemeName(scheme), shapes, edges, eligible,
        100.0 * static_cast<double>(eligible) / std::max(1L, edges), all.maxPositionError,
        all.maxNormalAngle, bfr, over129, over8, bfr / over129, bfr / over8);
  }
  std::printf("\n");
}

void printShapeTable(const std::vector<ShapeShare>& shares) {
  std::printf("| shape | scheme | edges | eligible | share |\n|---|---|---:|---:|---:|\n");
  for (const ShapeShare& s : shares) {
    std::printf("| %s | %s | %d | %d | %.1f%% |\n", s.name.c_str(), mesh::schemeName(s.scheme),
                s.edges, s.eligible, 100.0 * s.eligible / std::max(1, s.edges));
  }
  std::printf("\n");
}

}  // namespace

int main(int argc, char** argv) {
  const Options options = parse(argc, argv);
  std::vector<testing::NamedMesh> shapes = testing::ownShapes();
  for (testing::NamedMesh& s : testing::corpusShapes()) shapes.push_back(std::move(s));
  shapes = testing::selectShapes(std::move(shapes), options.shapes);
  const size_t searched = shapes.size();
  for (int n = silhouette::kMinTableValence; n <= silhouette::kMaxTableValence; ++n) {
    shapes.push_back({"split_prism_" + std::to_string(n), testing::splitPrism(n)});
    shapes.push_back({"split_bipyramid_" + std::to_string(n), testing::splitBipyramid(n)});
  }

  std::map<ClassKey, ClassStats> classes;
  std::vector<ShapeShare> shares;
  std::vector<SearchComparison> searches;
  for (size_t i = 0; i < shapes.size(); ++i) {
    const testing::NamedMesh& shape = shapes[i];
    if (shape.mesh.scheme == mesh::Scheme::Bilinear) continue;
    try {
      shares.push_back(measureShape(shape, options, classes));
      if (i < searched) searches.push_back(compareSearch(shape, options));
    } catch (const std::exception& e) {
      std::fprintf(stderr, "%s: %s\n", shape.name.c_str(), e.what());
    }
  }
  std::printf("### Per scheme\n\n");
  printSchemeTable(classes, shares);
  std::printf("### Per scheme and valence of the extraordinary end\n\n");
  printClassTable(classes);
  std::printf("### The contour search with and without the tables\n\n");
  printSearchTable(searches, options.views);
  std::printf("### Eligible edges per shape\n\n");
  printShapeTable(shares);
  return 0;
}
