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

// Marching cubes layer by layer: cells of layer k lie between corner layers k and k + 1. Edge
// vertices are shared through per-edge index arrays of the two corner layers, so each vertex is
// made once, by the first cell that needs it.
class LayerMarcher {
 public:
  LayerMarcher(const Grid& grid, RawMesh& out);
  void march(int k, const float* bottom, const float* top);
  size_t cellsWithSurface() const { return cellsWithSurface_; }

 private:
  const Grid& grid_;
  RawMesh& out_;
  std::vector<uint32_t> xBottom_, xTop_, yBottom_, yTop_, z_;
  std::vector<uint8_t> columns_;
  size_t cellsWithSurface_ = 0;
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
