// The slab marcher (render/implicit/grid.h) against the plain definition of marching cubes: for
// every cell in order (k, j, i), the case table's triangles, each crossed grid edge given one
// vertex the first time a cell uses it. On hand-made grids (a sphere, metaballs, random values
// full of ambiguous faces and saddles, values exactly at iso, every configuration of a single
// cube, rows across 64-bit word boundaries, surfaces cut by the grid's border) the marcher must
// draw the same triangles in the same order on the same edges with the same end values, make one
// vertex per crossed edge, be closed wherever the border does not cut the surface, and give the
// same mesh on 1 and 2 threads and whatever the slabs.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <functional>
#include <map>
#include <random>
#include <set>
#include <tuple>

#include "render/core/parallel.h"
#include "render/implicit/cube_table.h"
#include "render/implicit/grid.h"

namespace limn::render::implicit {
namespace {

// A grid edge: the corner it starts from and its axis.
using GridEdge = std::array<int, 4>;  // i, j, k, axis

// Corner values, x fastest, on a grid whose corner (i, j, k) sits at (i, j, k).
struct Samples {
  Grid grid;
  std::vector<float> values;

  Samples(int nx, int ny, int nz, const std::function<float(int, int, int)>& f) {
    grid.origin = {0, 0, 0};
    grid.cell = 1;
    grid.n[0] = nx;
    grid.n[1] = ny;
    grid.n[2] = nz;
    for (int k = 0; k <= nz; ++k)
      for (int j = 0; j <= ny; ++j)
        for (int i = 0; i <= nx; ++i) values.push_back(f(i, j, k));
  }
  float at(int i, int j, int k) const {
    return values[(static_cast<size_t>(k) * (grid.n[1] + 1) + j) * (grid.n[0] + 1) + i];
  }
};

// A mesh with its vertices named by their grid edges.
struct EdgeMesh {
  std::vector<GridEdge> vertices;
  std::vector<std::array<float, 2>> ends;  // fa, fb
  std::vector<uint32_t> indices;

  std::vector<GridEdge> triangleEdges() const {
    std::vector<GridEdge> out;
    for (uint32_t v : indices) out.push_back(vertices.at(v));
    return out;
  }
};

// Marching cubes as defined: cell by cell, vertices made by the first cell that needs them.
EdgeMesh referenceMarch(const Samples& s) {
  const CubeTable& table = CubeTable::instance();
  EdgeMesh mesh;
  std::map<GridEdge, uint32_t> made;
  for (int k = 0; k < s.grid.n[2]; ++k) {
    for (int j = 0; j < s.grid.n[1]; ++j) {
      for (int i = 0; i < s.grid.n[0]; ++i) {
        float v[8];
        for (int c = 0; c < 8; ++c) v[c] = s.at(i + (c & 1), j + ((c >> 1) & 1), k + (c >> 2));
        for (uint8_t e : table.triangles(cubeConfiguration(v))) {
          const CubeEdge& edge = cubeEdges()[e];
          const GridEdge key{i + (edge.a & 1), j + ((edge.a >> 1) & 1), k + (edge.a >> 2),
                             edge.axis};
          auto [at, fresh] = made.emplace(key, static_cast<uint32_t>(mesh.vertices.size()));
          if (fresh) {
            mesh.vertices.push_back(key);
            mesh.ends.push_back({v[edge.a], v[edge.b]});
          }
          mesh.indices.push_back(at->second);
        }
      }
    }
  }
  return mesh;
}

// The slab marcher's mesh, its vertices named by the edges their ends lie on.
EdgeMesh slabMarch(const Samples& s, int slab, unsigned threads) {
  RawMesh raw;
  SlabMarcher marcher(s.grid, raw);
  const size_t perLayer = s.grid.cornersPerLayer();
  parallelThreadLimit() = threads;
  for (int k0 = 0; k0 < s.grid.n[2]; k0 += slab) {
    marcher.march(k0, std::min(s.grid.n[2], k0 + slab), &s.values[k0 * perLayer]);
  }
  parallelThreadLimit() = 0;
  EdgeMesh mesh;
  mesh.indices = raw.indices;
  for (const EdgeVertex& v : raw.vertices) {
    const Vec3 d = v.b - v.a;
    const int axis = d.x == 1 ? 0 : d.y == 1 ? 1 : 2;
    EXPECT_EQ(length(d), 1.0) << "a vertex not on one grid edge";
    mesh.vertices.push_back({int(v.a.x), int(v.a.y), int(v.a.z), axis});
    mesh.ends.push_back({v.fa, v.fb});
  }
  return mesh;
}

// Whether the grid edges of two vertices lie in the same face of the grid's box.
bool onOneBorderFace(const Grid& grid, const GridEdge& e, const GridEdge& f) {
  for (int a = 0; a < 3; ++a) {
    for (int side : {0, grid.n[a]}) {
      if (e[3] != a && f[3] != a && e[a] == side && f[a] == side) return true;
    }
  }
  return false;
}

// Every vertex made once, used, and carrying its edge's two samples; the same triangles as the
// reference in the same order; edges used by two triangles in opposite directions, except along
// the grid's border.
void expectSameAsReference(const Samples& s, const std::string& what, bool touchesBorder = false) {
  const EdgeMesh reference = referenceMarch(s);
  for (int slab : {1, 2, 3, 16, s.grid.n[2]}) {
    const EdgeMesh mesh = slabMarch(s, slab, 1);
    const std::string where = what + ", slabs of " + std::to_string(slab);
    ASSERT_EQ(mesh.indices.size(), reference.indices.size()) << where;
    EXPECT_EQ(mesh.triangleEdges(), reference.triangleEdges()) << where;
    ASSERT_EQ(mesh.vertices.size(), reference.vertices.size()) << where;
    std::set<GridEdge> distinct(mesh.vertices.begin(), mesh.vertices.end());
    EXPECT_EQ(distinct.size(), mesh.vertices.size()) << where << ": an edge with two vertices";
    for (size_t v = 0; v < mesh.vertices.size(); ++v) {
      const GridEdge& e = mesh.vertices[v];
      const int di = e[3] == 0, dj = e[3] == 1, dk = e[3] == 2;
      ASSERT_EQ(mesh.ends[v][0], s.at(e[0], e[1], e[2])) << where;
      ASSERT_EQ(mesh.ends[v][1], s.at(e[0] + di, e[1] + dj, e[2] + dk)) << where;
      ASSERT_NE(mesh.ends[v][0] > 0, mesh.ends[v][1] > 0) << where << ": an uncrossed edge";
    }
  }
  const EdgeMesh mesh = slabMarch(s, 16, 1);
  std::map<std::pair<uint32_t, uint32_t>, int> directed;
  for (size_t t = 0; t < mesh.indices.size(); t += 3) {
    for (int c = 0; c < 3; ++c) ++directed[{mesh.indices[t + c], mesh.indices[t + (c + 1) % 3]}];
  }
  size_t borderEdges = 0;
  for (const auto& [edge, uses] : directed) {
    EXPECT_EQ(uses, 1) << what << ": an edge used twice in one direction";
    if (directed.count({edge.second, edge.first})) continue;
    ++borderEdges;
    EXPECT_TRUE(onOneBorderFace(s.grid, mesh.vertices[edge.first], mesh.vertices[edge.second]))
        << what << ": a hole inside the grid";
  }
  if (!touchesBorder) {
    EXPECT_EQ(borderEdges, 0u) << what;
  }
}

float sphere(int i, int j, int k, Vec3 centre, double radius) {
  return static_cast<float>(radius - length(Vec3{double(i), double(j), double(k)} - centre));
}

TEST(SlabMarcher, SphereIsTheReferenceMeshAndClosed) {
  Samples s(20, 20, 20, [](int i, int j, int k) {
    return sphere(i, j, k, {10.3, 9.8, 10.1}, 7.2);
  });
  expectSameAsReference(s, "sphere");
  EXPECT_GT(referenceMarch(s).indices.size(), 3000u);
}

TEST(SlabMarcher, MetaballsAreTheReferenceMeshAndClosed) {
  const Vec3 centres[] = {{8, 9, 7}, {14, 10, 9}, {11, 15, 8}, {20, 6, 10}};
  Samples s(28, 22, 18, [&](int i, int j, int k) {
    double f = 0;
    for (const Vec3& c : centres) {
      f += 4.0 / (1.0 + length(Vec3{double(i), double(j), double(k)} - c));
    }
    return static_cast<float>(f - 1.6);
  });
  expectSameAsReference(s, "metaballs");
}

TEST(SlabMarcher, RandomValuesFullOfSaddlesAreTheReferenceMesh) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-1, 1);
  Samples s(9, 7, 5, [&](int, int, int) { return u(rng); });
  expectSameAsReference(s, "random values", true);
  // Alternating signs: every face of every cell ambiguous.
  Samples checker(6, 5, 4, [](int i, int j, int k) { return (i + j + k) % 2 ? 1.0f : -1.0f; });
  expectSameAsReference(checker, "checkerboard", true);
}

TEST(SlabMarcher, ValuesExactlyAtIsoAreOutside) {
  std::mt19937 rng(5);
  Samples s(10, 8, 6, [&](int, int, int) { return static_cast<float>(int(rng() % 3) - 1); });
  expectSameAsReference(s, "values in {-1, 0, 1}", true);
  Samples zero(4, 4, 4,
               [](int i, int j, int k) { return i == 2 && j == 2 && k == 2 ? 0.0f : -1.0f; });
  EXPECT_TRUE(slabMarch(zero, 4, 1).indices.empty());
  Samples bump(4, 4, 4,
               [](int i, int j, int k) { return i == 2 && j == 2 && k == 2 ? 1e-30f : -0.0f; });
  expectSameAsReference(bump, "one corner just inside");
  EXPECT_EQ(slabMarch(bump, 4, 1).indices.size(), 8u * 3);
}

TEST(SlabMarcher, EveryConfigurationOfOneCube) {
  for (int configuration = 0; configuration < 256; ++configuration) {
    Samples s(1, 1, 1, [&](int i, int j, int k) {
      return (configuration >> (i + 2 * j + 4 * k)) & 1 ? 0.5f : -0.5f;
    });
    expectSameAsReference(s, "configuration " + std::to_string(configuration), true);
    EXPECT_EQ(slabMarch(s, 1, 1).indices.size(),
              CubeTable::instance().triangles(configuration).size());
  }
}

TEST(SlabMarcher, RowsAcrossWordBoundariesAndFlatGrids) {
  // 64 corners to a bit word: rows of 63 to 130 corners cross one word boundary or two.
  for (int nx : {62, 63, 64, 65, 127, 128, 129}) {
    Samples s(nx, 3, 2, [&](int i, int j, int k) {
      return static_cast<float>(std::sin(0.37 * i + 1.3 * j) + 0.6 * std::cos(0.9 * k + 0.21 * i));
    });
    expectSameAsReference(s, "nx " + std::to_string(nx), true);
  }
  Samples column(1, 1, 40, [](int i, int j, int k) { return std::sin(0.5f * k + i - j); });
  expectSameAsReference(column, "a 1x1x40 column", true);
  Samples slab(40, 30, 1, [](int i, int j, int k) { return sphere(i, j, k, {20, 15, 0.5}, 9); });
  expectSameAsReference(slab, "one layer of cells", true);
}

TEST(SlabMarcher, SurfaceCutByTheBorder) {
  // A sphere centred on the grid's corner and one bulging out of a face: open only where the
  // border cuts them.
  Samples corner(12, 10, 9, [](int i, int j, int k) {
    return sphere(i, j, k, {0.2, 0.3, 0.1}, 6.5);
  });
  expectSameAsReference(corner, "sphere at the corner", true);
  Samples face(16, 16, 12, [](int i, int j, int k) { return sphere(i, j, k, {8, 8, 12.4}, 5.3); });
  expectSameAsReference(face, "sphere through the top face", true);
  // Everything inside: no cell has a sign change, not even on the border.
  Samples full(5, 5, 5, [](int, int, int) { return 1.0f; });
  EXPECT_TRUE(slabMarch(full, 2, 1).indices.empty());
}

TEST(SlabMarcher, SameMeshOnOneAndTwoThreads) {
  // Wavy sheets through the whole grid. The marcher hands out rows about 2^18 corners at a time:
  // at 129 corners a row, slabs of 16 layers and more are at least two tasks, so both threads
  // take part.
  Samples s(128, 128, 64, [](int i, int j, int k) {
    return std::sin(0.31f * i) + std::sin(0.23f * j + 0.4f) + std::sin(0.27f * k + 0.1f * i);
  });
  const EdgeMesh one = slabMarch(s, 64, 1);
  ASSERT_GT(one.indices.size(), 100000u);
  for (int slab : {64, 32, 16}) {
    const EdgeMesh two = slabMarch(s, slab, 2);
    EXPECT_EQ(two.indices, one.indices) << "slabs of " << slab;
    EXPECT_EQ(two.vertices, one.vertices) << "slabs of " << slab;
  }
}

}  // namespace
}  // namespace limn::render::implicit
