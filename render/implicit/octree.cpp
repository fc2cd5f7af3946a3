// The octree polygoniser: cells are split only where the surface may pass (a sign change among
// 27 samples, or samples too close to iso for the field's Lipschitz bound to rule a crossing
// out) and is curved (two normals among the samples further apart than `flatness`), down to the
// grid's cell size. The leaves are polygonised by dual marching cubes (Schaefer and Warren): each
// vertex of the octree that is a corner of some leaf gives a dual cell whose eight corners are
// the centres of the eight leaves around it (some of them the same leaf: the cell collapses), and
// marching cubes runs on those eight values. Neighbouring dual cells share their faces exactly,
// whatever the leaves' sizes, so the mesh is closed with no T-junctions; vertices are identified
// by the pair of leaves at the ends of their dual edge.
#include <algorithm>
#include <cmath>
#include <unordered_map>
#include <unordered_set>

#include "render/core/parallel.h"
#include "render/implicit/cube_table.h"
#include "render/implicit/grid.h"

namespace limn::render::implicit {

namespace {

struct Node {
  int level;
  int i, j, k;      // position in units of this node's size
  int child = -1;   // first of 8 children (index into nodes), -1 for a leaf
  float value = 0;  // F - iso at the centre
};

class Octree {
 public:
  Octree(const Field& field, const Grid& grid, double flatness, const CancelToken& cancel)
      : field_(field), flatness_(flatness), cancel_(cancel) {
    // Root: the grid with a margin of kMargin cells, rounded up to a power of two, so that every
    // leaf near the surface is surrounded by leaves (dual cells only fill between leaf centres).
    const int cells = std::max({grid.n[0], grid.n[1], grid.n[2]}) + 2 * kMargin;
    while ((1 << depth_) < cells) ++depth_;
    cell_ = grid.cell;
    origin_ = grid.origin - Vec3{1, 1, 1} * (kMargin * cell_);
    minLevel_ = std::max(0, depth_ - 4);
  }

  void build(PolygonizerStats& stats) {
    nodes_.push_back({0, 0, 0, 0});
    std::vector<int> level = {0};
    while (!level.empty()) {
      cancel_.check();
      std::vector<char> split(level.size());
      std::vector<float> centre(level.size());
      parallelFor(level.size(), 64, [&](size_t begin, size_t end) {
        FieldEvaluator evaluator(field_);
        for (size_t n = begin; n < end; ++n) {
          split[n] = shouldSplit(nodes_[level[n]], evaluator, centre[n]);
        }
      });
      std::vector<int> next;
      for (size_t n = 0; n < level.size(); ++n) {
        nodes_[level[n]].value = centre[n];
        stats.fieldSamples +=
            nodes_[level[n]].level >= minLevel_ && nodes_[level[n]].level < depth_ ? 27 : 1;
        if (!split[n]) continue;
        const Node parent = nodes_[level[n]];
        nodes_[level[n]].child = static_cast<int>(nodes_.size());
        for (int c = 0; c < 8; ++c) {
          next.push_back(static_cast<int>(nodes_.size()));
          nodes_.push_back({parent.level + 1, 2 * parent.i + (c & 1), 2 * parent.j + ((c >> 1) & 1),
                            2 * parent.k + ((c >> 2) & 1)});
        }
      }
      level = std::move(next);
    }
    for (const Node& node : nodes_) stats.octreeLeaves += node.child < 0;
  }

  void polygonize(RawMesh& out, PolygonizerStats& stats) {
    const int side = 1 << depth_;  // finest cells along the root
    std::unordered_set<uint64_t> seen;
    std::unordered_map<uint64_t, uint32_t> vertices;
    const CubeTable& table = CubeTable::instance();
    const auto& edges = cubeEdges();
    size_t visited = 0;
    for (size_t n = 0; n < nodes_.size(); ++n) {
      if (nodes_[n].child >= 0) continue;
      if ((++visited & 4095) == 0) cancel_.check();
      const Node& leaf = nodes_[n];
      const int size = side >> leaf.level;
      for (int c = 0; c < 8; ++c) {
        const int x = (leaf.i + (c & 1)) * size, y = (leaf.j + ((c >> 1) & 1)) * size,
                  z = (leaf.k + ((c >> 2) & 1)) * size;
        if (x == 0 || y == 0 || z == 0 || x == side || y == side || z == side) continue;
        const uint64_t key = (static_cast<uint64_t>(x) * (side + 1) + y) * (side + 1) + z;
        if (!seen.insert(key).second) continue;
        int corners[8];
        float values[8];
        for (int d = 0; d < 8; ++d) {
          corners[d] = locate(2 * x + ((d & 1) ? 1 : -1), 2 * y + ((d & 2) ? 1 : -1),
                              2 * z + ((d & 4) ? 1 : -1));
          values[d] = nodes_[corners[d]].value;
        }
        const int configuration = cubeConfiguration(values);
        if (configuration == 0 || configuration == 255) continue;
        ++stats.cellsVisited;
        const std::vector<uint8_t>& triangles = table.triangles(configuration);
        for (size_t t = 0; t < triangles.size(); t += 3) {
          uint32_t ids[3];
          for (int v = 0; v < 3; ++v) {
            const CubeEdge& edge = edges[triangles[t + v]];
            ids[v] = vertexOn(corners[edge.a], corners[edge.b], vertices, out);
          }
          // A collapsed dual cell can give two of a triangle's edges the same pair of leaves.
          if (ids[0] == ids[1] || ids[1] == ids[2] || ids[2] == ids[0]) continue;
          out.indices.insert(out.indices.end(), ids, ids + 3);
        }
      }
    }
  }

 private:
  static constexpr int kMargin = 16;

  double nodeSize(const Node& node) const { return cell_ * ((1 << depth_) >> node.level); }
  Vec3 nodeCorner(const Node& node) const {
    const double s = nodeSize(node);
    return origin_ + Vec3{node.i * s, node.j * s, node.k * s};
  }
  Vec3 centre(const Node& node) const {
    return nodeCorner(node) + Vec3{1, 1, 1} * (0.5 * nodeSize(node));
  }

  bool overlapsDomain(const Node& node) const {
    const Vec3 lo = nodeCorner(node), hi = lo + Vec3{1, 1, 1} * nodeSize(node);
    const Bounds& d = field_.bounds();
    return lo.x <= d.hi.x && hi.x >= d.lo.x && lo.y <= d.hi.y && hi.y >= d.lo.y && lo.z <= d.hi.z &&
           hi.z >= d.lo.z;
  }

  bool shouldSplit(const Node& node, FieldEvaluator& field, float& centreValue) const {
    if (node.level >= depth_ || node.level < minLevel_) {
      centreValue = static_cast<float>(field.value(centre(node)));
      return node.level < depth_ && overlapsDomain(node);
    }
    const double s = nodeSize(node);
    const Vec3 corner = nodeCorner(node);
    double values[27];
    Vec3 normals[27];
    int count = 0;
    bool inside = false, outside = false;
    double nearest = 1e300;
    for (int c = 0; c < 27; ++c) {
      const Vec3 p = corner + Vec3{c % 3 * 0.5 * s, c / 3 % 3 * 0.5 * s, c / 9 * 0.5 * s};
      Vec3 g;
      values[c] = field.valueAndGradient(p, g);
      (values[c] > 0 ? inside : outside) = true;
      nearest = std::min(nearest, std::fabs(values[c]));
      const double len = length(g);
      if (len > 0) normals[count++] = g / len;
    }
    centreValue = static_cast<float>(values[13]);
    if (!(inside && outside)) {
      // No sign change among the samples: split only if the field could still cross iso
      // between them (every point is within s sqrt(3) / 4 of a sample).
      const double reach = s * std::sqrt(3.0) / 4.0;
      return nearest <= field.lipschitzNear(centre(node), s) * reach;
    }
    for (int a = 0; a < count; ++a) {
      for (int b = a + 1; b < count; ++b) {
        if (dot(normals[a], normals[b]) < flatness_) return true;
      }
    }
    return false;
  }

  // The leaf containing the point at doubled finest-cell coordinates (x2, y2, z2) (odd values:
  // never on a cell boundary).
  int locate(int x2, int y2, int z2) const {
    int n = 0;
    while (nodes_[n].child >= 0) {
      const Node& node = nodes_[n];
      const int half = (1 << depth_) >> (node.level + 1);  // child size in finest cells
      const int cx = (x2 / 2 - node.i * 2 * half) >= half;
      const int cy = (y2 / 2 - node.j * 2 * half) >= half;
      const int cz = (z2 / 2 - node.k * 2 * half) >= half;
      n = node.child + cx + 2 * cy + 4 * cz;
    }
    return n;
  }

  uint32_t vertexOn(int a, int b, std::unordered_map<uint64_t, uint32_t>& vertices,
                    RawMesh& out) const {
    if (a > b) std::swap(a, b);
    const uint64_t key = (static_cast<uint64_t>(a) << 32) | static_cast<uint32_t>(b);
    auto [it, inserted] = vertices.emplace(key, 0);
    if (inserted) {
      it->second =
          out.addVertex(centre(nodes_[a]), centre(nodes_[b]), nodes_[a].value, nodes_[b].value);
    }
    return it->second;
  }

  const Field& field_;
  double flatness_;
  const CancelToken& cancel_;
  int depth_ = 0, minLevel_ = 0;
  double cell_ = 1;
  Vec3 origin_;
  std::vector<Node> nodes_;
};

}  // namespace

void octreeSurface(const Field& field, const Grid& grid, double flatness, RawMesh& out,
                   PolygonizerStats& stats, const CancelToken& cancel) {
  Octree octree(field, grid, flatness, cancel);
  octree.build(stats);
  octree.polygonize(out, stats);
}

}  // namespace limn::render::implicit
