// MeshBuffers: a TriangleMesh's vertex and index data on the GPU, with the vertex arrays that
// draw its triangles and its edges. Created once per Rasterizer and refilled for every render
// (the buffer objects are kept; only their storage is replaced).
#pragma once

#include "render/raster/gl_api.h"
#include "render/tessellate/triangle_mesh.h"

namespace limn::render::raster {

class MeshBuffers {
 public:
  MeshBuffers();
  ~MeshBuffers();
  MeshBuffers(const MeshBuffers&) = delete;
  MeshBuffers& operator=(const MeshBuffers&) = delete;

  // Uploads positions, normals (when there is one per vertex), texture coordinates (when
  // `withTexcoords` and there is one per vertex), albedo colours (when there is one per vertex),
  // triangle indices and edges. Throws std::invalid_argument for indices out of range or mismatched
  // array sizes.
  void upload(const tessellate::TriangleMesh& mesh, bool withTexcoords);

  bool hasNormals() const { return hasNormals_; }
  void drawTriangles() const;
  // mesh.lines as GL_LINES, or every triangle's outline when the mesh has no lines.
  void drawEdges() const;

 private:
  GLuint triangleArray_ = 0, lineArray_ = 0;
  GLuint positions_ = 0, normals_ = 0, texcoords_ = 0, albedo_ = 0, triangleIndices_ = 0,
         lineIndices_ = 0;
  GLsizei triangleIndexCount_ = 0, lineIndexCount_ = 0;
  bool hasNormals_ = false;
};

}  // namespace limn::render::raster
