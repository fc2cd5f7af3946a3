// ControlMesh: a subdivision control cage as a client described it: points, faces, and the
// tags that shape the limit surface (creases, corners, holes, boundary and crease rules).
// Readers in api/ build it; validateMesh() checks it before anything uses it, so every later
// stage may assume indices are in range and the scheme can take the faces.
#pragma once

#include <string>
#include <vector>

#include "render/core/vec.h"

namespace limn::render::mesh {

enum class Scheme { CatmullClark, Loop, Bilinear };
enum class BoundaryInterpolation { None, EdgeOnly, EdgeAndCorner };
enum class CreaseMethod { Uniform, Chaikin };
enum class TriangleSubdivision { CatmullClark, Smooth };

// Sharpness at or above this is infinitely sharp (OpenSubdiv's SHARPNESS_INFINITE).
inline constexpr float kInfiniteSharpness = 10.0f;

struct Crease {
  int v0 = 0, v1 = 0;
  float sharpness = 0;
};

struct Corner {
  int vertex = 0;
  float sharpness = 0;
};

struct ControlMesh {
  Scheme scheme = Scheme::CatmullClark;
  std::vector<Vec3> points;
  std::vector<int> faceVertexCounts;
  std::vector<int> faceVertexIndices;
  std::vector<Crease> creases;
  std::vector<Corner> corners;
  std::vector<int> holes;  // face indices
  BoundaryInterpolation boundary = BoundaryInterpolation::EdgeOnly;
  CreaseMethod creaseMethod = CreaseMethod::Uniform;
  TriangleSubdivision triangleSubdivision = TriangleSubdivision::CatmullClark;

  int vertexCount() const { return static_cast<int>(points.size()); }
  int faceCount() const { return static_cast<int>(faceVertexCounts.size()); }
  Bounds bounds() const;
};

// The largest coordinate magnitude a mesh may have: the rasteriser works in float, and squared
// distances of coordinates beyond this lose all precision (1e300 would overflow to infinity).
inline constexpr double kMaxCoordinate = 1e15;

struct MeshLimits {
  int maxVertices = 200000;
  int maxFaces = 200000;
  int maxFaceSize = 64;  // vertices in one face
  int maxValence = 512;  // faces around one vertex (422 naming the vertex beyond it)
};

// Throws InputError (InvalidMesh naming the face, vertex, crease or corner — also for a vertex
// over maxValence; LimitExceeded naming the limit) when the mesh cannot be used.
void validateMesh(const ControlMesh& mesh, const MeshLimits& limits);

const char* schemeName(Scheme scheme);

}  // namespace limn::render::mesh
