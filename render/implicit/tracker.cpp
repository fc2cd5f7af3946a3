// The surface tracker: marching cubes on the cells the surface passes through only. Seeds are
// the cells with a sign change on the six axis lines through every positive primitive's centre;
// from them the search continues across every cell face whose corners have mixed signs (the
// table draws a segment on exactly those faces, so the neighbour holds the surface's
// continuation). Field values are sampled wave by wave on all threads and cached by corner.
#include <algorithm>
#include <unordered_map>
#include <unordered_set>

#include "render/core/parallel.h"
#include "render/implicit/cube_table.h"
#include "render/implicit/grid.h"

namespace limn::render::implicit {

namespace {

struct CellIndex {
  int i, j, k;
};

class Tracker {
 public:
  Tracker(const Field& field, const Grid& grid, RawMesh& out, const CancelToken& cancel)
      : field_(field), grid_(grid), out_(out), cancel_(cancel) {}

  void run(PolygonizerStats& stats) {
    std::vector<CellIndex> frontier = seeds();
    while (!frontier.empty()) {
      cancel_.check();
      sample(frontier);
      std::vector<CellIndex> next;
      for (const CellIndex& cell : frontier) visit(cell, next);
      frontier = std::move(next);
    }
    stats.cellsVisited = visited_.size();
    stats.fieldSamples = values_.size();
  }

 private:
  uint64_t cornerKey(int i, int j, int k) const {
    return static_cast<uint64_t>(i) +
           static_cast<uint64_t>(grid_.n[0] + 1) *
               (static_cast<uint64_t>(j) + static_cast<uint64_t>(grid_.n[1] + 1) * k);
  }
  uint64_t cellKey(const CellIndex& c) const { return cornerKey(c.i, c.j, c.k); }
  bool inGrid(const CellIndex& c) const {
    return c.i >= 0 && c.j >= 0 && c.k >= 0 && c.i < grid_.n[0] && c.j < grid_.n[1] &&
           c.k < grid_.n[2];
  }

  // Samples every corner of `cells` not yet known, on all threads.
  void sample(const std::vector<CellIndex>& cells) {
    std::vector<uint64_t> missing;
    std::vector<CellIndex> corners;
    for (const CellIndex& c : cells) {
      for (int corner = 0; corner < 8; ++corner) {
        CellIndex p{c.i + (corner & 1), c.j + ((corner >> 1) & 1), c.k + ((corner >> 2) & 1)};
        uint64_t key = cornerKey(p.i, p.j, p.k);
        if (values_.emplace(key, 0.0f).second) {
          missing.push_back(key);
          corners.push_back(p);
        }
      }
    }
    std::vector<float> sampled(missing.size());
    parallelFor(missing.size(), 256, [&](size_t begin, size_t end) {
      FieldEvaluator evaluator(field_);
      for (size_t m = begin; m < end; ++m) {
        sampled[m] = static_cast<float>(
            evaluator.value(grid_.corner(corners[m].i, corners[m].j, corners[m].k)));
      }
    });
    for (size_t m = 0; m < missing.size(); ++m) values_[missing[m]] = sampled[m];
  }

  void cornerValues(const CellIndex& c, float v[8]) const {
    for (int corner = 0; corner < 8; ++corner) {
      v[corner] = values_.at(
          cornerKey(c.i + (corner & 1), c.j + ((corner >> 1) & 1), c.k + ((corner >> 2) & 1)));
    }
  }

  // Cells with a sign change on the axis lines through each positive primitive's centre.
  std::vector<CellIndex> seeds() {
    std::vector<CellIndex> line, found;
    for (const PreparedPrimitive& prim : field_.primitives()) {
      if (prim.sign < 0) continue;
      Vec3 centre =
          prim.spec.type == PrimitiveType::Expression
              ? (prim.spec.bounds.empty() ? field_.bounds().center() : prim.spec.bounds.center())
              : prim.origin;
      Vec3 g = (centre - grid_.origin) / grid_.cell;
      CellIndex start{std::clamp(static_cast<int>(g.x), 0, grid_.n[0] - 1),
                      std::clamp(static_cast<int>(g.y), 0, grid_.n[1] - 1),
                      std::clamp(static_cast<int>(g.z), 0, grid_.n[2] - 1)};
      for (int axis = 0; axis < 3; ++axis) {
        for (int step = 0; step < grid_.n[axis]; ++step) {
          CellIndex c = start;
          (axis == 0 ? c.i : axis == 1 ? c.j : c.k) = step;
          line.push_back(c);
        }
      }
    }
    sample(line);
    for (const CellIndex& c : line) {
      float v[8];
      cornerValues(c, v);
      int configuration = cubeConfiguration(v);
      if (configuration != 0 && configuration != 255 && visited_.insert(cellKey(c)).second) {
        found.push_back(c);
      }
    }
    return found;
  }

  void visit(const CellIndex& c, std::vector<CellIndex>& next) {
    float v[8];
    cornerValues(c, v);
    const int configuration = cubeConfiguration(v);
    const auto& edges = cubeEdges();
    for (uint8_t e : CubeTable::instance().triangles(configuration)) {
      const CubeEdge& edge = edges[e];
      const int a = edge.a, b = edge.b;
      const int ai = c.i + (a & 1), aj = c.j + ((a >> 1) & 1), ak = c.k + ((a >> 2) & 1);
      const uint64_t key = cornerKey(ai, aj, ak) * 3 + edge.axis;
      auto [it, inserted] = edgeVertices_.emplace(key, 0);
      if (inserted) {
        it->second = out_.addVertex(
            grid_.corner(ai, aj, ak),
            grid_.corner(c.i + (b & 1), c.j + ((b >> 1) & 1), c.k + ((b >> 2) & 1)), v[a], v[b]);
      }
      out_.indices.push_back(it->second);
    }
    // Faces with mixed signs: x = 0, x = 1, y = 0, y = 1, z = 0, z = 1.
    static constexpr int kFaces[6][4] = {{0, 2, 4, 6}, {1, 3, 5, 7}, {0, 1, 4, 5},
                                         {2, 3, 6, 7}, {0, 1, 2, 3}, {4, 5, 6, 7}};
    static constexpr int kStep[6][3] = {{-1, 0, 0}, {1, 0, 0},  {0, -1, 0},
                                        {0, 1, 0},  {0, 0, -1}, {0, 0, 1}};
    for (int f = 0; f < 6; ++f) {
      int inside = 0;
      for (int corner : kFaces[f]) inside += v[corner] > 0.0f;
      if (inside == 0 || inside == 4) continue;
      CellIndex n{c.i + kStep[f][0], c.j + kStep[f][1], c.k + kStep[f][2]};
      if (inGrid(n) && visited_.insert(cellKey(n)).second) next.push_back(n);
    }
  }

  const Field& field_;
  const Grid& grid_;
  RawMesh& out_;
  const CancelToken& cancel_;
  std::unordered_map<uint64_t, float> values_;
  std::unordered_map<uint64_t, uint32_t> edgeVertices_;
  std::unordered_set<uint64_t> visited_;
};

}  // namespace

void trackSurface(const Field& field, const Grid& grid, RawMesh& out, PolygonizerStats& stats,
                  const CancelToken& cancel) {
  Tracker(field, grid, out, cancel).run(stats);
}

}  // namespace limn::render::implicit
