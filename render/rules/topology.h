// Topology: the connectivity of one level of a subdivision mesh, with the sharpness and hole
// tags that the rules read, in flat (offset + index) arrays.
//
// fromMesh() builds the base level of a ControlMesh: edges are found through a hash map keyed
// by their two vertex indices and numbered in order of first appearance in the face list, with
// the vertex order of the face that first names them (OpenSubdiv's Vtr numbers its base edges
// the same way). The refiners in this folder build each child level directly, numbering its
// components the way OpenSubdiv's Far numbers a uniformly refined level (see refine.h), so that
// a level refined here and one refined by Far can be compared vertex by vertex.
//
// The tags follow OpenSubdiv's Far factory: boundary edges are infinitely sharp; with
// "edge-and-corner" boundaries a vertex with one face and two edges is an infinitely sharp
// corner; with "none" the faces around a boundary vertex become holes unless all its boundary
// edges were tagged infinitely sharp. Only manifold, consistently oriented meshes are accepted
// (fromMesh throws InputError otherwise).
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "render/mesh/control_mesh.h"

namespace limn::render::rules {

// Sharpness at or above this is infinitely sharp (Sdc::Crease::SHARPNESS_INFINITE).
inline constexpr float kInfinitelySharp = mesh::kInfiniteSharpness;

// Scheme and rule options a level carries to its children.
struct SchemeOptions {
  mesh::Scheme scheme = mesh::Scheme::CatmullClark;
  mesh::BoundaryInterpolation boundary = mesh::BoundaryInterpolation::EdgeOnly;
  mesh::CreaseMethod creaseMethod = mesh::CreaseMethod::Uniform;
  mesh::TriangleSubdivision triangleSubdivision = mesh::TriangleSubdivision::CatmullClark;
};

struct Topology {
  SchemeOptions options;
  int vertexCount = 0;

  // ---- Faces: vertices and edges per corner; faceEdges[k] joins corners k and k+1 ----
  std::vector<int> faceOffsets{0};  // faceCount() + 1 entries
  std::vector<int> faceVertices;
  std::vector<int> faceEdges;
  std::vector<uint8_t> faceHole;

  // ---- Edges: their two vertices, their faces ----
  std::vector<std::array<int, 2>> edgeVertices;
  std::vector<int> edgeFaceOffsets, edgeFaces;

  // ---- Vertices: incident edges and faces (in index order, not around the vertex) ----
  std::vector<int> vertexEdgeOffsets, vertexEdges;
  std::vector<int> vertexFaceOffsets, vertexFaces;

  // Per vertex, the face its counter-clockwise ring starts at, as OpenSubdiv orders it (see
  // orderedRing); empty or -1: the vertex's lowest-numbered face. Only read at interior vertices.
  std::vector<int> ringStart;

  // ---- Tags ----
  std::vector<float> edgeSharpness;    // boundary edges are kInfinitelySharp
  std::vector<float> vertexSharpness;  // corners

  int faceCount() const { return static_cast<int>(faceOffsets.size()) - 1; }
  int edgeCount() const { return static_cast<int>(edgeVertices.size()); }
  int faceSize(int f) const { return faceOffsets[f + 1] - faceOffsets[f]; }
  std::span<const int> faceVerts(int f) const {
    return {faceVertices.data() + faceOffsets[f], static_cast<size_t>(faceSize(f))};
  }
  std::span<const int> faceEdgesOf(int f) const {
    return {faceEdges.data() + faceOffsets[f], static_cast<size_t>(faceSize(f))};
  }
  std::span<const int> edgeFacesOf(int e) const {
    return {edgeFaces.data() + edgeFaceOffsets[e],
            static_cast<size_t>(edgeFaceOffsets[e + 1] - edgeFaceOffsets[e])};
  }
  std::span<const int> vertexEdgesOf(int v) const {
    return {vertexEdges.data() + vertexEdgeOffsets[v],
            static_cast<size_t>(vertexEdgeOffsets[v + 1] - vertexEdgeOffsets[v])};
  }
  std::span<const int> vertexFacesOf(int v) const {
    return {vertexFaces.data() + vertexFaceOffsets[v],
            static_cast<size_t>(vertexFaceOffsets[v + 1] - vertexFaceOffsets[v])};
  }
  bool isBoundaryEdge(int e) const { return edgeFaceOffsets[e + 1] - edgeFaceOffsets[e] < 2; }
  int otherVertex(int e, int v) const {
    return edgeVertices[e][0] == v ? edgeVertices[e][1] : edgeVertices[e][0];
  }
  // Position of vertex v among the corners of face f.
  int cornerOf(int f, int v) const;

  // Fills edgeFaces (each edge's faces in face order), vertexEdges and vertexFaces from
  // faceVertices, faceEdges and edgeVertices.
  void completeAdjacency();

  // The base level of a validated ControlMesh. Throws InputError(InvalidMesh) naming the edge
  // or vertex where the mesh is not manifold or not consistently oriented.
  static Topology fromMesh(const mesh::ControlMesh& mesh);
};

// The faces and edges around one vertex in counter-clockwise order (seen from the side the
// faces' counter-clockwise winding faces). Face i lies between edges i and i+1; edge i is the
// edge from the vertex to the next corner of face i. A boundary vertex starts at the face whose
// leading edge is a boundary edge and has one more edge than faces; an interior vertex starts
// at ringStart[v] (the lowest-numbered face at the base level, where OpenSubdiv starts too;
// refined levels inherit OpenSubdiv's starts from their parents) and has as many edges as faces.
struct VertexRing {
  std::vector<int> faces;
  std::vector<int> edges;
  std::vector<int> corners;  // position of the vertex in each face
  bool boundary = false;
};
VertexRing orderedRing(const Topology& topology, int v);
// The same into `ring`, reusing its storage.
void orderedRing(const Topology& topology, int v, VertexRing& ring);

}  // namespace limn::render::rules
