// What the polygonisers share (internal to render/implicit): the regular grid over the field's
// domain, the field sampled on it in layers, marching cubes over consecutive layers, and the
// raw mesh whose vertices still lie at their cell edges' linear interpolation.
#pragma once

#include <cstdint>
#include <vector>

#include "render/core/cancel.h"
#include "render/core/vec.h"
#include "render/implicit/field.h"
#include "render/implicit/polygonize.h"

namespace limn::render::implicit {

struct Grid {
  Vec3 origin;
  double cell = 1;
  int n[3] = {1, 1, 1};  // cells along x, y, z; corners are n + 1

  Vec3 corner(int i, int j, int k) const { return origin + Vec3{i * cell, j * cell, k * cell}; }
  size_t cornersPerLayer() const { return static_cast<size_t>(n[0] + 1) * (n[1] + 1); }
};

// `resolution` cells along the domain's longest side, one cell of margin all round so that the
// surface (inside the domain) never touches the grid's border.
Grid makeGrid(const Bounds& domain, int resolution);

// F - iso at the corners of layers k0..k1 (inclusive), layer after layer, x fastest; all threads.
void sampleLayers(const Field& field, const Grid& grid, int k0, int k1, float* out,
                  const CancelToken& cancel);

// A vertex on the segment a-b, where the field changes sign (fa and fb: F - iso at the ends).
struct EdgeVertex {
  Vec3 a, b;
  float fa, fb;
};

struct RawMesh {
  std::vector<EdgeVertex> vertices;
  std::vector<uint32_t> indices;  // three per triangle
  uint32_t addVertex(const Vec3& a, const Vec3& b, float fa, float fb) {
    vertices.push_back({a, b, fa, fb});
    return static_cast<uint32_t>(vertices.size() - 1);
  }
};

// The cube configuration of eight corner values (bit c set: corner c inside, value > 0).
inline int cubeConfiguration(const float v[8]) {
  int configuration = 0;
  for (int c = 0; c < 8; ++c) configuration |= (v[c] > 0.0f) << c;
  return configuration;
}

// Marching cubes over slabs of consecutive layers, edge by edge and in parallel. A row of
// corners (fixed j, k) owns the grid edges that start at its corners: its x edges, its y edges
// (to row j + 1) and its z edges (to layer k + 1). Each slab is marched in passes over its rows,
// every pass on all threads (parallelFor) and with no locks:
//   1. classify: each row's corners as inside bits (value > 0), 64 to a word;
//   2. count, from the bits alone: the crossed edges each row owns and the triangles of the row
//      of cells above it; cells whose eight corners agree are skipped a word at a time, so only
//      the rows' trimmed runs of surface cells cost anything;
//   3. prefix sums of the counts (serial: one number per row);
//   4. write each row's vertices and triangles at their offsets. A vertex's index is its row's
//      offset plus its rank among the row's crossed edges of its axis (a popcount), so a cell
//      finds the vertices of its twelve edges without an index array or a hash map.
// Every crossed edge gets exactly one vertex. Vertices are numbered layer by layer (a layer's x
// and y edges row by row, then its z edges row by row), triangles in cell order (k, j, i), so
// the mesh is the same whatever the number of threads, with the triangles the case table draws.
class SlabMarcher {
 public:
  SlabMarcher(const Grid& grid, RawMesh& out);
  // The cells of layers k0..k1 - 1, from F - iso at corner layers k0..k1 (`values`, x fastest).
  // Slabs must come in order, each starting at the layer where the previous one ended.
  void march(int k0, int k1, const float* values);

 private:
  struct Slab;
  struct CellRow;
  struct EdgeRun;
  void classify(const Slab& slab);
  void count(const Slab& slab);
  void assignOffsets(const Slab& slab);
  void write(const Slab& slab);
  void writeXYVertices(const Slab& slab, size_t r);
  void writeZVertices(const Slab& slab, size_t r);
  void writeTriangles(size_t r);
  bool uniform(size_t r, bool nextRow, bool nextLayer) const;
  size_t rowsPerTask() const;
  CellRow cellRow(size_t r, bool withNeighbours) const;

  const Grid& grid_;
  RawMesh& out_;
  int words_;                        // bit words per row of corners, one of them zero padding
  std::vector<uint64_t> bits_;       // the slab's rows of inside bits
  std::vector<uint32_t> xyVertex_;   // per row: its x and y edges' count, then first vertex
  std::vector<uint32_t> zVertex_;    // per row: its z edges' count, then first vertex
  std::vector<uint32_t> xVertices_;  // per row: its crossed x edges (its y vertices follow them)
  std::vector<uint16_t> ranks_;      // per row, axis and word: the row's crossed edges before it
                                     // (16 bits: rows of at most 65,535 corners, checked)
  std::vector<uint32_t> triangle_;   // per row: its row of cells' triangles, then first triangle
  enum : uint8_t { kXYVertices = 1, kZVertices = 2, kTriangles = 4 };
  std::vector<uint8_t> work_;  // per row: what it has to write
  enum : uint8_t { kAllOutside, kAllInside, kMixed };
  std::vector<uint8_t> state_;  // per row: its corners all outside, all inside, or mixed
  uint32_t layerVertex_ = 0;    // the first vertex of the next slab's first layer
};

// The vertices moved from their linear interpolation onto the surface (regula falsi on the
// field along their edge, to `tolerance` world units) with the gradient's normals, as a mesh.
tessellate::TriangleMesh finishVertices(const Field& field, const RawMesh& raw, double tolerance,
                                        const CancelToken& cancel);

// The tracker's and the octree's cells.
void trackSurface(const Field& field, const Grid& grid, RawMesh& out, PolygonizerStats& stats,
                  const CancelToken& cancel);
void octreeSurface(const Field& field, const Grid& grid, double flatness, RawMesh& out,
                   PolygonizerStats& stats, const CancelToken& cancel);

}  // namespace limn::render::implicit
