#include "render/mesh/control_mesh.h"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <unordered_set>

#include "render/core/error.h"

namespace limn::render::mesh {

namespace {

[[noreturn]] void invalid(const std::string& subject, const std::string& message) {
  throw InputError(InputError::Kind::InvalidMesh, subject, message);
}

[[noreturn]] void overLimit(const std::string& limit, long value, long max) {
  throw InputError(
      InputError::Kind::LimitExceeded, limit,
      "mesh exceeds limit " + limit + ": " + std::to_string(value) + " > " + std::to_string(max));
}

uint64_t edgeKey(int a, int b) {
  if (a > b) std::swap(a, b);
  return (static_cast<uint64_t>(static_cast<uint32_t>(a)) << 32) | static_cast<uint32_t>(b);
}

void checkSharpness(float s, const std::string& subject) {
  if (!std::isfinite(s) || s < 0)
    invalid(subject, subject + " has sharpness " + std::to_string(s) + ": must be finite and >= 0");
}

// The number of face corners at each vertex (its valence on a closed manifold) against the
// limit: the limit surface around a vertex of valence n costs about n^3 to build (OpenSubdiv's
// patch of every face around it has O(n) points of O(n) weights each), so a small mesh with one
// vertex of very high valence could hold a worker for minutes.
void checkValence(const ControlMesh& mesh, int maxValence) {
  std::vector<int> corners(mesh.points.size(), 0);
  for (int v : mesh.faceVertexIndices) ++corners[v];
  for (size_t v = 0; v < corners.size(); ++v) {
    if (corners[v] <= maxValence) continue;
    const std::string vertex = "vertex " + std::to_string(v);
    invalid(vertex, vertex + " has " + std::to_string(corners[v]) +
                        " faces around it: exceeds limit maxValence (" +
                        std::to_string(maxValence) + ")");
  }
}

}  // namespace

Bounds ControlMesh::bounds() const {
  Bounds b;
  for (const Vec3& p : points) b.extend(p);
  return b;
}

const char* schemeName(Scheme scheme) {
  switch (scheme) {
    case Scheme::CatmullClark:
      return "catmull-clark";
    case Scheme::Loop:
      return "loop";
    case Scheme::Bilinear:
      return "bilinear";
  }
  return "?";
}

void validateMesh(const ControlMesh& mesh, const MeshLimits& limits) {
  if (mesh.points.empty()) invalid("points", "mesh has no vertices");
  if (mesh.faceVertexCounts.empty()) invalid("faces", "mesh has no faces");
  if (mesh.vertexCount() > limits.maxVertices) {
    overLimit("maxVertices", mesh.vertexCount(), limits.maxVertices);
  }
  if (mesh.faceCount() > limits.maxFaces) overLimit("maxFaces", mesh.faceCount(), limits.maxFaces);

  for (int v = 0; v < mesh.vertexCount(); ++v) {
    const Vec3& p = mesh.points[v];
    if (!isFinite(p)) {
      invalid("vertex " + std::to_string(v),
              "vertex " + std::to_string(v) + " has a non-finite coordinate");
    }
    if (std::fmax(std::fabs(p.x), std::fmax(std::fabs(p.y), std::fabs(p.z))) > kMaxCoordinate) {
      char coordinates[96];
      std::snprintf(coordinates, sizeof coordinates, "(%g, %g, %g)", p.x, p.y, p.z);
      invalid("vertex " + std::to_string(v), "vertex " + std::to_string(v) + " at " + coordinates +
                                                 " has a coordinate beyond +-1e15");
    }
  }

  std::unordered_set<uint64_t> edges;
  size_t offset = 0;
  for (int f = 0; f < mesh.faceCount(); ++f) {
    const std::string face = "face " + std::to_string(f);
    int n = mesh.faceVertexCounts[f];
    if (n < 3) invalid(face, face + " has " + std::to_string(n) + " vertices: at least 3 needed");
    if (n > limits.maxFaceSize) {
      throw InputError(InputError::Kind::LimitExceeded, "maxFaceSize",
                       face + " has " + std::to_string(n) +
                           " vertices: exceeds limit maxFaceSize " +
                           std::to_string(limits.maxFaceSize));
    }
    if (mesh.scheme == Scheme::Loop && n != 3) {
      invalid(face, face + " has " + std::to_string(n) +
                        " vertices: the loop scheme takes triangles only");
    }
    if (offset + n > mesh.faceVertexIndices.size()) {
      invalid("faceVertexIndices",
              "faceVertexIndices has " + std::to_string(mesh.faceVertexIndices.size()) +
                  " entries but faceVertexCounts needs more (at " + face + ")");
    }
    // A face may repeat a vertex (the corpus's non-manifold shapes do): OpenSubdiv accepts
    // such faces as non-manifold topology, so limn does too.
    for (int i = 0; i < n; ++i) {
      int v = mesh.faceVertexIndices[offset + i];
      if (v < 0 || v >= mesh.vertexCount()) {
        invalid(face, face + " refers to vertex " + std::to_string(v) + ", outside 0.." +
                          std::to_string(mesh.vertexCount() - 1));
      }
    }
    for (int i = 0; i < n; ++i) {
      edges.insert(edgeKey(mesh.faceVertexIndices[offset + i],
                           mesh.faceVertexIndices[offset + (i + 1) % n]));
    }
    offset += n;
  }
  if (offset != mesh.faceVertexIndices.size()) {
    invalid("faceVertexIndices",
            "faceVertexIndices has " + std::to_string(mesh.faceVertexIndices.size()) +
                " entries but faceVertexCounts sums to " + std::to_string(offset));
  }
  checkValence(mesh, limits.maxValence);

  for (size_t c = 0; c < mesh.creases.size(); ++c) {
    const Crease& crease = mesh.creases[c];
    const std::string subject = "crease " + std::to_string(c);
    checkSharpness(crease.sharpness, subject);
    if (crease.v0 < 0 || crease.v0 >= mesh.vertexCount() || crease.v1 < 0 ||
        crease.v1 >= mesh.vertexCount()) {
      invalid(subject, subject + " refers to vertex outside 0.." +
                           std::to_string(mesh.vertexCount() - 1) + " (" +
                           std::to_string(crease.v0) + "-" + std::to_string(crease.v1) + ")");
    }
    if (!edges.count(edgeKey(crease.v0, crease.v1))) {
      invalid(subject, subject + " is on edge " + std::to_string(crease.v0) + "-" +
                           std::to_string(crease.v1) + ", which is not an edge of the mesh");
    }
  }
  for (size_t c = 0; c < mesh.corners.size(); ++c) {
    const std::string subject = "corner " + std::to_string(c);
    checkSharpness(mesh.corners[c].sharpness, subject);
    int v = mesh.corners[c].vertex;
    if (v < 0 || v >= mesh.vertexCount()) {
      invalid(subject, subject + " refers to vertex " + std::to_string(v) + ", outside 0.." +
                           std::to_string(mesh.vertexCount() - 1));
    }
  }
  for (size_t h = 0; h < mesh.holes.size(); ++h) {
    int f = mesh.holes[h];
    if (f < 0 || f >= mesh.faceCount()) {
      invalid("hole " + std::to_string(h), "hole " + std::to_string(h) + " refers to face " +
                                               std::to_string(f) + ", outside 0.." +
                                               std::to_string(mesh.faceCount() - 1));
    }
  }
  if (static_cast<int>(mesh.holes.size()) >= mesh.faceCount()) {
    std::unordered_set<int> distinct(mesh.holes.begin(), mesh.holes.end());
    if (static_cast<int>(distinct.size()) == mesh.faceCount()) {
      throw InputError(InputError::Kind::EmptySurface, "holes",
                       "every face is a hole: the mesh has no surface to render");
    }
  }
}

}  // namespace limn::render::mesh
