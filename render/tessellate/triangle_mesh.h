// TriangleMesh: the output of every method, what raster/ draws and metrics/ measures.
// Besides positions and normals it remembers where it lies on the limit surface, so the
// geometric error of any approximation can be measured against the exact surface.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "render/core/image.h"
#include "render/core/vec.h"

namespace limn::render::tessellate {

struct TriangleMesh {
  std::vector<Vec3f> positions;
  std::vector<Vec3f> normals;     // per vertex, unit; used for smooth shading
  std::vector<uint32_t> indices;  // three per triangle, counter-clockwise seen from outside

  // Where each triangle lies on the limit surface: the base face it belongs to and the
  // (u, v) of its three corners in that face's parameterisation. Filled by methods that
  // tessellate the limit surface (adaptive, reference); empty otherwise.
  std::vector<int32_t> triangleFaces;
  std::vector<Vec2f> cornerUVs;  // three per triangle

  // For meshes whose vertices approximate the limit surface (coarse, uniform): each vertex's
  // own limit position (the geometry metric compares vertices with these).
  std::vector<Vec3f> limitPositions;

  // Edges to draw in the wireframe pass, two indices each; empty means "triangle edges".
  // Coarse and uniform meshes list their polygon edges so quads are drawn as quads.
  std::vector<uint32_t> lines;

  // For Shading::NormalMap: per-vertex coordinates into normalMap, and the map itself (3
  // channels, float, unit world-space normals; see render/normalmap/normal_atlas.h). Texture
  // coordinates are in [0, 1]^2 with (0, 0) at the top-left corner of the image: s runs along
  // a row, t down the rows (row 0 of the Image at t = 0), texel (i, j)'s centre at
  // ((i + 0.5) / width, (j + 0.5) / height). Empty / null: no normal map.
  std::vector<Vec2f> texcoords;
  std::shared_ptr<const Image> normalMap;

  // Per-vertex front-face albedo in [0, 1] (the "patches" image colours each patch); empty:
  // shading's front albedo. Back faces keep the back albedo either way.
  std::vector<Vec3f> albedo;

  // Every piece closed and wound outward, without cracks (set for adaptive meshes of such a
  // surface, undisplaced): from an eye outside it, each back face lies behind a front face, so
  // the rasteriser need not draw back faces while the whole mesh is in front of the near plane.
  bool closedOutward = false;

  size_t triangleCount() const { return indices.size() / 3; }
  size_t vertexCount() const { return positions.size(); }
};

}  // namespace limn::render::tessellate
