// Polygonisers of an implicit surface F = iso (field.h) into a closed TriangleMesh:
//
//   marching-cubes  every cell of a regular grid (`resolution` cells along the domain's longest
//                   side), in slabs of layers sampled on all threads then marched in order;
//   tracker         the same cells and triangles, visiting only the cells the surface passes
//                   through, by continuation from seed cells found on axis lines through every
//                   positive primitive's centre;
//   octree          cells subdivided only where the surface may pass and is curved (normals
//                   differ by more than `flatness`), down to the grid's cell size, polygonised by
//                   dual marching cubes (each octree vertex's cell of leaf centres), which is
//                   closed by construction across cells of different sizes;
//   adaptive        a marching-cubes mesh at `resolution` (coarse: it sets what topology is
//                   found), whose edges are split
//                   where the normals at their ends differ by more than `flatness` (up to
//                   `maxDepth` times), the new vertices moved onto the surface; triangles with
//                   one, two or three split edges become two, three or four, so no T-junction
//                   is ever left.
//
// Vertices on a cell edge (or dual edge) are identified by that edge's integer index, never by
// hashing coordinates; they are placed by root-finding on the edge (regula falsi on the field,
// `epsilon` of the domain's diagonal), and their normals are the field's gradient.
#pragma once

#include <cstddef>

#include "render/core/cancel.h"
#include "render/implicit/field.h"
#include "render/tessellate/triangle_mesh.h"

namespace limn::render::implicit {

enum class PolygonizerMethod { MarchingCubes, Tracker, Octree, Adaptive };

const char* polygonizerName(PolygonizerMethod method);

struct PolygonizerOptions {
  PolygonizerMethod method = PolygonizerMethod::MarchingCubes;
  int resolution = 80;    // cells along the longest side of the domain
  double flatness = 0.9;  // octree, adaptive: cosine between normals below which to refine
  double epsilon = 1e-6;  // root-finding and projection tolerance, relative to the diagonal
  int maxDepth = 3;       // adaptive: rounds of edge splitting
  size_t maxTriangles = 8'000'000;
};

struct PolygonizerStats {
  size_t cellsVisited = 0;  // grid cells (or dual cells) polygonised or examined
  size_t fieldSamples = 0;  // field values sampled on the grid / at octree nodes
  size_t octreeLeaves = 0;
  size_t edgesSplit = 0;         // adaptive
  int gridCells[3] = {0, 0, 0};  // along x, y, z
  double cellSize = 0;
  double sampleMs = 0;      // sampling the field on the grid
  double polygonizeMs = 0;  // the cells' triangles
  double vertexMs = 0;      // root-finding and normals of the vertices
  double sampleMvoxelsPerS = 0;
};

struct Polygonization {
  tessellate::TriangleMesh mesh;
  PolygonizerStats stats;
};

// Throws InputError for options out of range, a LimitExceeded error past maxTriangles, and
// Cancelled when `cancel` expires (checked every layer, every few thousand cells or vertices).
Polygonization polygonize(const Field& field, const PolygonizerOptions& options,
                          const CancelToken& cancel);

// How closed a triangle mesh is: edges (by vertex indices) used by one triangle, by more than
// two, or twice in the same direction (inconsistent orientation).
struct MeshClosure {
  size_t boundaryEdges = 0, nonManifoldEdges = 0, misorientedEdges = 0;
  bool closed() const { return boundaryEdges == 0 && nonManifoldEdges == 0; }
};
MeshClosure checkClosure(const tessellate::TriangleMesh& mesh);

// The geometric error of a mesh against the isosurface: |F(p) - iso| / |grad F(p)| at each
// triangle's vertices, edge midpoints and centroid (a first-order distance to the surface).
struct ImplicitGeometryError {
  double maxDist = 0, meanDist = 0;        // world units
  double relMaxDist = 0, relMeanDist = 0;  // relative to the field domain's diagonal
};
ImplicitGeometryError measureImplicitGeometry(const tessellate::TriangleMesh& mesh,
                                              const Field& field, const CancelToken& cancel);

}  // namespace limn::render::implicit
