#include "render/silhouette/silhouette_mesh.h"

#include <string>

#include "render/core/error.h"
#include "render/core/parallel.h"
#include "render/silhouette/face_triangulation.h"

namespace limn::render::silhouette {

namespace {

// What one face contributes, built independently of the others.
struct FacePiece {
  std::vector<FacePoint> points;
  std::vector<std::array<int, 3>> triangles;
  std::vector<ContourCurve> curves;
  bool corrected = false;
  size_t coarseTriangles = 0, curveSamples = 0, unresolved = 0;
  bool odd = false;
};

FacePiece buildFace(const subdiv::LimitSurface& surface, const Camera& camera,
                    const ContourSearch& search, const SilhouetteOptions& options, int face) {
  FacePiece piece;
  FaceBoundary boundary = faceBoundary(surface, search, face);
  const int corners = static_cast<int>(boundary.points.size()) - boundary.edgePointCount;
  piece.coarseTriangles = static_cast<size_t>(corners - 2);
  piece.points = boundary.points;
  if (boundary.edgePointCount == 0) {
    for (int k = 1; k + 1 < corners; ++k) piece.triangles.push_back({0, k, k + 1});
    return piece;
  }
  piece.corrected = true;
  std::vector<FaceCurve> curves = faceCurves(surface, camera, boundary, options.curves, &piece.odd);
  std::vector<CurvePath> paths;
  for (FaceCurve& curve : curves) {
    CurvePath path{curve.from, curve.to, {}};
    ContourCurve contour;
    contour.face = face;
    contour.fromEdge = boundary.edge[curve.from];
    contour.fromPoint = boundary.edgePoint[curve.from];
    contour.toEdge = boundary.edge[curve.to];
    contour.toPoint = boundary.edgePoint[curve.to];
    contour.points.push_back(boundary.points[curve.from]);
    for (FacePoint& sample : curve.samples) {
      path.interior.push_back(static_cast<int>(piece.points.size()));
      piece.points.push_back(sample);
      contour.points.push_back(sample);
    }
    contour.points.push_back(boundary.points[curve.to]);
    piece.curveSamples += curve.samples.size();
    piece.unresolved += curve.unresolved;
    paths.push_back(std::move(path));
    piece.curves.push_back(std::move(contour));
  }
  std::vector<Vec2> uv;
  uv.reserve(piece.points.size());
  for (const FacePoint& p : piece.points) uv.push_back(p.uv);
  piece.triangles = triangulateFace(uv, static_cast<int>(boundary.points.size()), paths);
  return piece;
}

}  // namespace

SilhouetteMesh buildSilhouetteMesh(const subdiv::LimitSurface& surface, const Camera& camera,
                                   const SilhouetteOptions& options, const CancelToken& cancel) {
  SilhouetteMesh out;
  out.search = searchContour(surface, camera, options.search, cancel);
  out.stats.search = out.search.stats;

  const int faceCount = surface.faceCount();
  std::vector<FacePiece> pieces(faceCount);
  parallelFor(faceCount, 32, [&](size_t begin, size_t end) {
    for (size_t f = begin; f < end; ++f) {
      if ((f & 63) == 0) cancel.check();
      if (!surface.hasLimit(static_cast<int>(f))) continue;
      pieces[f] = buildFace(surface, camera, out.search, options, static_cast<int>(f));
    }
  });
  cancel.check();

  size_t triangles = 0;
  for (const FacePiece& piece : pieces) triangles += piece.triangles.size();
  if (triangles > options.maxTriangles) {
    throw InputError(InputError::Kind::LimitExceeded, "maxTriangles",
                     "the silhouette mesh would have " + std::to_string(triangles) +
                         " triangles: exceeds limit maxTriangles " +
                         std::to_string(options.maxTriangles));
  }

  // Every face gets its own vertices (positions shared bit for bit along common edges), so
  // normals may differ across sharp features and per-face attributes can be added.
  tessellate::TriangleMesh& mesh = out.mesh;
  out.corrected.assign(faceCount, false);
  for (int f = 0; f < faceCount; ++f) {
    FacePiece& piece = pieces[f];
    if (piece.points.empty()) continue;
    const uint32_t first = static_cast<uint32_t>(mesh.positions.size());
    for (const FacePoint& p : piece.points) {
      mesh.positions.emplace_back(p.position);
      mesh.normals.emplace_back(p.normal);
      mesh.limitPositions.emplace_back(p.position);
    }
    for (const std::array<int, 3>& t : piece.triangles) {
      for (int k : t) {
        mesh.indices.push_back(first + static_cast<uint32_t>(k));
        const Vec2& uv = piece.points[k].uv;
        mesh.cornerUVs.push_back({static_cast<float>(uv.x), static_cast<float>(uv.y)});
      }
      mesh.triangleFaces.push_back(f);
    }
    out.corrected[f] = piece.corrected;
    if (piece.corrected) {
      ++out.stats.correctedFaces;
      if (!piece.curves.empty()) ++out.stats.contourFaces;
      if (piece.triangles.size() > piece.coarseTriangles) {
        out.stats.trianglesAdded += piece.triangles.size() - piece.coarseTriangles;
      }
    }
    out.stats.curveSamples += piece.curveSamples;
    out.stats.unresolvedSamples += piece.unresolved;
    if (piece.odd) ++out.stats.oddFaces;
    for (ContourCurve& c : piece.curves) out.curves.push_back(std::move(c));
  }
  out.stats.trianglesDrawn = mesh.triangleCount();
  return out;
}

}  // namespace limn::render::silhouette
