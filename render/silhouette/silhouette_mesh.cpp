#include "render/silhouette/silhouette_mesh.h"

#include <opensubdiv/bfr/tessellation.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "render/core/error.h"
#include "render/core/parallel.h"
#include "render/silhouette/chord_refinement.h"
#include "render/silhouette/face_refinement.h"
#include "render/silhouette/face_triangulation.h"

namespace limn::render::silhouette {

namespace Far = OpenSubdiv::Far;

namespace {

// What one face contributes, built independently of the others.
struct FacePiece {
  std::vector<FacePoint> points;
  std::vector<std::array<int, 3>> triangles;
  std::vector<ContourCurve> curves;
  bool corrected = false;
  size_t coarseTriangles = 0, curveSamples = 0, unresolved = 0;
  int splits = 0;
  bool odd = false;
  size_t culled = 0;      // triangles left out as hidden (cullHidden)
  bool thinFold = false;  // two of its contour curves pass within kFoldSliverPx in the image
};

// A ring face refined by refineConcaveChords: Bfr's tessellation with the face's edge rates
// and an inner rate. Its boundary points are exactly the face's (corner 0, the points of edge
// 0, corner 1, ...) when every edge carries only its uniform points; false otherwise, and for
// faces whose domain is not Bfr's (face_domain.h).
bool tessellateRingFace(const FaceDomains& domains, const ContourSearch& search,
                        const ChordRefinement& chords, const FaceBoundary& boundary,
                        FacePiece& piece) {
  namespace Bfr = OpenSubdiv::Bfr;
  const subdiv::LimitSurface& surface = domains.surface();
  const int face = boundary.face;
  if (surface.parameterization(face).HasSubFaces()) return false;
  OpenSubdiv::Far::ConstIndexArray edges = surface.baseLevel().GetFaceEdges(face);
  std::vector<int> rates;
  for (int e : edges) {
    int rate = std::max(1, chords.edgeRates[e]);
    if (search.edgePoints[e].size() != static_cast<size_t>(rate - 1)) return false;
    rates.push_back(rate);
  }
  rates.push_back(chords.interiorRates[face]);
  Bfr::Tessellation tess(surface.parameterization(face), static_cast<int>(rates.size()),
                         rates.data());
  if (tess.GetNumBoundaryCoords() != static_cast<int>(boundary.points.size())) return false;
  std::vector<double> coords(2 * tess.GetNumCoords());
  tess.GetCoords(coords.data());
  for (int i = tess.GetNumBoundaryCoords(); i < tess.GetNumCoords(); ++i) {
    subdiv::LimitSample s = surface.evaluate(face, coords[2 * i], coords[2 * i + 1]);
    piece.points.push_back({{coords[2 * i], coords[2 * i + 1]}, s.position, s.normal});
  }
  std::vector<int> facets(3 * tess.GetNumFacets());
  tess.GetFacets(facets.data());
  for (size_t i = 0; i < facets.size(); i += 3) {
    piece.triangles.push_back({facets[i], facets[i + 1], facets[i + 2]});
  }
  return true;
}

// A face holding a contour loop (ContourSearch::loopFaces) is drawn as Bfr's tessellation
// with this inner rate: segments about kLoopSegmentPx long across the face's projection, so
// that the tessellation's own outline follows the loop (a polygon of such segments around a
// loop of radius r px stays within kLoopSegmentPx^2 / (8 r) of it), at most kMaxLoopRate.
// Corners behind the eye (the eye so close that the face fills the view) get the most.
constexpr double kLoopSegmentPx = 2.0;
constexpr int kMaxLoopRate = 64;

int loopRate(const FaceDomains& domains, const Camera& camera, int face) {
  std::vector<Vec3> corners;
  for (int k = 0; k < domains.size(face); ++k) {
    const Vec3 p = camera.project(domains.position(face, domains.corner(face, k)));
    if (p.z <= camera.nearPlane()) return kMaxLoopRate;
    corners.push_back(p);
  }
  double span = 0;
  for (const Vec3& a : corners) {
    for (const Vec3& b : corners) span = std::max(span, std::hypot(a.x - b.x, a.y - b.y));
  }
  return std::clamp(static_cast<int>(std::ceil(span / kLoopSegmentPx)), 4, kMaxLoopRate);
}

// Leaves out triangles that cannot be seen. On a closed piece (LimitSurface::hiddenSide), every
// triangle that faces away from the eye: it is hidden there, but its flat chord lies on the eye's
// side of the true surface, so next to an inner contour it could poke through the front's chords,
// which lie behind it (the dark fringes of back faces along a fold). A corner faces away when the
// cosine between its limit normal and the view ray is above kBackFacingCos; corners on the contour
// (cosine about 0) do not say which side a triangle is on, so a triangle with no corner facing
// the eye is decided by its (u, v) centre.
// On any surface, open ones too, a triangle whose three corners lie on the contour curve and
// whose centre faces away: it belongs to the back sheet of a fold, which the front sheet
// covers where the outline is convex; where the outline is concave (a spike's flanks, a
// curved strip seen edge-on) its chord spans the concavity and stands pixels past the outline.
// On a closed piece, a face where two contour curves pass within kFoldSliverPx of each other in
// the image holds a fold thinner than their chords' error: the chords can cross and open a gap
// between the front sheets that only the fold's own back-facing triangles cover (a dotted line
// of missing pixels tens of pixels long on a ribbed cactus seen along a rib). There, hidden
// triangles lying within kFoldSliverPx of the face's contour curves in the image are kept: they
// can neither darken nor move the outline by more than that. (Keeping only those with a corner
// on a curve and thinner than kFoldSliverPx, as before, left a 0.1 x 1.5 px hole in the ribbed
// cactus from another view, covered by the fold's triangles a little wider than that.)
constexpr double kBackFacingCos = 1e-3;
constexpr double kFoldSliverPx = 1.0;

// Whether a point of polyline `a` lies within kFoldSliverPx of a segment of polyline `b` that
// does not end at that point (`a` and `b` may be one curve: a hairpin whose legs nearly meet).
bool curvesCloseInImage(const std::vector<Vec2>& a, const std::vector<Vec2>& b) {
  const bool same = &a == &b;
  for (size_t i = 0; i < a.size(); ++i) {
    for (size_t k = 0; k + 1 < b.size(); ++k) {
      if (same && (k + 1 >= i && k <= i)) continue;  // segments through point i
      if (distanceToSegment2D(a[i], b[k], b[k + 1]) < kFoldSliverPx) return true;
    }
  }
  return false;
}

// The contour curves' points in the image plane.
std::vector<std::vector<Vec2>> projectedCurves(const Camera& camera,
                                               const std::vector<ContourCurve>& curves) {
  std::vector<std::vector<Vec2>> projected(curves.size());
  for (size_t i = 0; i < curves.size(); ++i) {
    for (const FacePoint& p : curves[i].points) {
      const Vec3 q = camera.project(p.position);
      projected[i].push_back({q.x, q.y});
    }
  }
  return projected;
}

bool hasThinFold(const Camera& camera, const std::vector<ContourCurve>& curves) {
  const std::vector<std::vector<Vec2>> projected = projectedCurves(camera, curves);
  for (size_t i = 0; i < projected.size(); ++i) {
    for (size_t j = i; j < projected.size(); ++j) {
      if (curvesCloseInImage(projected[i], projected[j]) ||
          (i != j && curvesCloseInImage(projected[j], projected[i]))) {
        return true;
      }
    }
  }
  return false;
}

// Whether the triangle lies within kFoldSliverPx of the curves in the image: its corners, edge
// midpoints and centre do (so it lies in the band the fold's chords can open, and no chord of
// it spans a concave stretch of the curves by more than that).
bool withinFoldBand(const Camera& camera, const std::vector<std::vector<Vec2>>& curves,
                    const std::array<Vec3, 3>& corners) {
  Vec2 c[3];
  for (int k = 0; k < 3; ++k) {
    const Vec3 q = camera.project(corners[k]);
    c[k] = {q.x, q.y};
  }
  const Vec2 probes[7] = {c[0],
                          c[1],
                          c[2],
                          {(c[0].x + c[1].x) / 2, (c[0].y + c[1].y) / 2},
                          {(c[1].x + c[2].x) / 2, (c[1].y + c[2].y) / 2},
                          {(c[2].x + c[0].x) / 2, (c[2].y + c[0].y) / 2},
                          {(c[0].x + c[1].x + c[2].x) / 3, (c[0].y + c[1].y + c[2].y) / 3}};
  for (const Vec2& p : probes) {
    bool near = false;
    for (const std::vector<Vec2>& curve : curves) {
      for (size_t k = 0; k < curve.size() && !near; ++k) {
        near = distanceToSegment2D(p, curve[k], curve[std::min(k + 1, curve.size() - 1)]) <
               kFoldSliverPx;
      }
      if (near) break;
    }
    if (!near) return false;
  }
  return true;
}

size_t cullHidden(const FaceDomains& domains, const Camera& camera, int face, FacePiece& piece) {
  const bool closed = domains.surface().hiddenSide(face) != 0;
  const int outward = domains.surface().outwardSign(face);
  auto facing = [&](const Vec3& position, const Vec3& normal) {
    const double cosine =
        outward * contourFunction(camera, position, normal) / length(camera.viewVector(position));
    return cosine > kBackFacingCos ? 1 : cosine < -kBackFacingCos ? -1 : 0;
  };
  std::vector<int> side(piece.points.size());
  for (size_t i = 0; i < piece.points.size(); ++i) {
    side[i] = facing(piece.points[i].position, piece.points[i].normal);
  }
  const bool keepFoldBand = closed && piece.thinFold;
  const std::vector<std::vector<Vec2>> curves =
      keepFoldBand ? projectedCurves(camera, piece.curves) : std::vector<std::vector<Vec2>>{};
  const size_t before = piece.triangles.size();
  std::erase_if(piece.triangles, [&](const std::array<int, 3>& t) {
    const int a = side[t[0]], b = side[t[1]], c = side[t[2]];
    if (a < 0 || b < 0 || c < 0) return false;
    if (keepFoldBand && withinFoldBand(camera, curves,
                                       {piece.points[t[0]].position, piece.points[t[1]].position,
                                        piece.points[t[2]].position})) {
      return false;
    }
    if (a > 0 && b > 0 && c > 0) return closed;
    if (!closed && (a != 0 || b != 0 || c != 0)) return false;
    const Vec2& ua = piece.points[t[0]].uv;
    const Vec2& ub = piece.points[t[1]].uv;
    const Vec2& uc = piece.points[t[2]].uv;
    const subdiv::LimitSample centre =
        domains.evaluate(face, {(ua.x + ub.x + uc.x) / 3, (ua.y + ub.y + uc.y) / 3});
    return facing(centre.position, centre.normal) > 0;
  });
  return before - piece.triangles.size();
}

// The boundary's corners and edge points in the plane that fits them best (Newell's normal),
// with axes whose cross product is that normal: a boundary counter-clockwise about it is
// counter-clockwise in the plane. Empty when there is no such plane (a degenerate boundary).
std::vector<Vec2> boundaryInBestPlane(const std::vector<FacePoint>& boundary) {
  const size_t n = boundary.size();
  Vec3 normal{0, 0, 0};
  for (size_t i = 0; i < n; ++i) {
    const Vec3& a = boundary[i].position;
    const Vec3& b = boundary[(i + 1) % n].position;
    normal += Vec3{(a.y - b.y) * (a.z + b.z), (a.z - b.z) * (a.x + b.x), (a.x - b.x) * (a.y + b.y)};
  }
  if (!(length(normal) > 0)) return {};
  normal = normalize(normal);
  const Vec3 helper = std::abs(normal.x) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
  const Vec3 xAxis = normalize(cross(helper, normal)), yAxis = cross(normal, xAxis);
  std::vector<Vec2> planar(n);
  for (size_t i = 0; i < n; ++i) {
    planar[i] = {dot(boundary[i].position, xAxis), dot(boundary[i].position, yAxis)};
  }
  return planar;
}

// Whether the boundary, laid in its best plane, is a simple polygon that turns back (a reflex
// corner more than kReflexTurn off straight). Such a face is concave where it lies, and a
// triangulation of its (u, v) domain, convex, spans the concave stretch with chords that leave
// the face: the flat cap of a gear, cut into quads, whose rim turns back at every tooth root,
// drew a chord 17 px long a few pixels outside the rim (the held-out gear, 3.19 px). A boundary
// that folds over itself in the plane (a face wrapping most of a thin tube) is not clipped there.
bool concaveInBestPlane(const std::vector<Vec2>& planar) {
  constexpr double kReflexTurn = 1e-3;  // sine of the turn: rounding on straight runs is not one
  const size_t n = planar.size();       // 0 when the boundary has no plane
  bool reflex = false;
  for (size_t i = 0; i < n && !reflex; ++i) {
    const Vec2 &a = planar[(i + n - 1) % n], &b = planar[i], &c = planar[(i + 1) % n];
    const double ab = std::hypot(b.x - a.x, b.y - a.y), bc = std::hypot(c.x - b.x, c.y - b.y);
    reflex = cross2(a, b, c) < -kReflexTurn * ab * bc;
  }
  if (!reflex) return false;
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = i + 2; j < n; ++j) {
      if (i == 0 && j == n - 1) continue;  // neighbours around the wrap
      if (segmentsCross(planar[i], planar[i + 1], planar[j], planar[(j + 1) % n])) return false;
    }
  }
  return true;
}

// The boundary of a face (its corners and edge points, counter-clockwise in (u, v)),
// triangulated where it lies: ear-clipped in its best plane, with the triangles' corners in the
// boundary's order as a fan's are. The face's domain is a regular polygon, convex, and so is any
// triangulation made in it, but the face need not be: the flat cap of a gear is a concave
// 64-gon, and a triangulation of its domain drew chords from one tooth to the next across the
// gaps between them (the held-out workshop from below, 17.6 px outside the outline).
std::vector<std::array<int, 3>> clipBoundaryInSpace(const std::vector<FacePoint>& boundary,
                                                    const std::vector<Vec2>& planar) {
  const int n = static_cast<int>(boundary.size());
  std::vector<std::array<int, 3>> triangles;
  if (planar.empty()) {  // no plane to clip in
    for (int k = 1; k + 1 < n; ++k) triangles.push_back({0, k, k + 1});
    return triangles;
  }
  std::vector<int> polygon(n);
  for (int i = 0; i < n; ++i) polygon[i] = i;
  earClip(planar, polygon, triangles);
  return triangles;
}

std::vector<std::array<int, 3>> clipBoundaryInSpace(const std::vector<FacePoint>& boundary) {
  return clipBoundaryInSpace(boundary, boundaryInBestPlane(boundary));
}

FacePiece buildFace(const FaceDomains& domains, const Camera& camera, const ContourSearch& search,
                    const ChordRefinement& chords, const SilhouetteOptions& options, int face) {
  const subdiv::LimitSurface& surface = domains.surface();
  FacePiece piece;
  FaceBoundary boundary = faceBoundary(domains, search, face);
  const int corners = static_cast<int>(boundary.points.size()) - boundary.edgePointCount;
  piece.coarseTriangles = static_cast<size_t>(corners - 2);
  piece.points = boundary.points;
  if (chords.interiorRates[face] >= 2) {
    piece.corrected = true;
    if (tessellateRingFace(domains, search, chords, boundary, piece)) return piece;
    piece.points = boundary.points;  // fall back to clipping the boundary alone
  }
  if (boundary.edgePointCount == 0) {
    if (corners > 4) {
      piece.triangles = clipBoundaryInSpace(boundary.points);
    } else {
      for (int k = 1; k + 1 < corners; ++k) piece.triangles.push_back({0, k, k + 1});
    }
    return piece;
  }
  piece.corrected = true;
  std::vector<FaceCurve> curves = faceCurves(domains, camera, boundary, options.curves, &piece.odd);
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
  piece.thinFold = hasThinFold(camera, piece.curves);
  std::vector<Vec2> uv;
  uv.reserve(piece.points.size());
  for (const FacePoint& p : piece.points) uv.push_back(p.uv);
  // Contour curves cut the face in its domain; a face without any is clipped where it lies
  // when it has more than four corners or is concave there.
  const std::vector<Vec2> planar =
      paths.empty() ? boundaryInBestPlane(boundary.points) : std::vector<Vec2>{};
  piece.triangles = paths.empty() && (corners > 4 || concaveInBestPlane(planar))
                        ? clipBoundaryInSpace(boundary.points, planar)
                        : triangulateFace(uv, static_cast<int>(boundary.points.size()), paths);
  // Only exact curves lie on the surface; a chord ending at a pn sample (off the surface) would
  // never come within tolerance, so pn faces keep their ear-clipped triangles.
  // Faces along an infinitely sharp interior edge are left as clipped: the surface can pinch
  // there (two (u, v) points on one position), and splitting towards it folded triangles over
  // each other in tests. Boundary edges (infinitely sharp to Far as well) do not pinch, and the
  // faces along them need the splits as much as any: a strip seen edge-on bends its outline.
  const Far::TopologyLevel& base = surface.baseLevel();
  bool sharpSide = false;
  for (int e : base.GetFaceEdges(face)) {
    sharpSide = sharpSide ||
                (!base.IsEdgeBoundary(e) && base.GetEdgeSharpness(e) >= mesh::kInfiniteSharpness);
  }
  bool cusp = false;  // at an infinitely sharp corner
  for (int v : base.GetFaceVertices(face)) {
    cusp = cusp ||
           (!base.IsVertexBoundary(v) && base.GetVertexSharpness(v) >= mesh::kInfiniteSharpness);
  }
  // A ring face whose edges carry more than their uniform points (a crossing seen from the
  // neighbour only) had no Bfr tessellation above; its ear-clipped fan is split the same way.
  const bool ringFallback = chords.interiorRates[face] >= 2;
  if ((!paths.empty() || ringFallback) && options.curves.mode == CurveMode::Exact && !sharpSide) {
    std::vector<std::vector<int>> chains;
    for (const CurvePath& path : paths) {
      std::vector<int> chain{path.from};
      chain.insert(chain.end(), path.interior.begin(), path.interior.end());
      chain.push_back(path.to);
      chains.push_back(std::move(chain));
    }
    // Hidden triangles go first, so that none is split only to be left out.
    if (options.cullHidden) piece.culled += cullHidden(domains, camera, face, piece);
    piece.splits =
        refineFaceTriangles(domains, camera, face, static_cast<int>(boundary.points.size()), chains,
                            options.chords.tolerancePx,
                            cusp ? options.chords.maxCuspFaceSplits : options.chords.maxFaceSplits,
                            piece.points, piece.triangles);
  }
  return piece;
}

}  // namespace

SilhouetteMesh buildSilhouetteMesh(const subdiv::LimitSurface& surface, const Camera& camera,
                                   const SilhouetteOptions& options, const CancelToken& cancel) {
  SilhouetteMesh out;
  const FaceDomains domains(surface);
  out.search = searchContour(domains, camera, options.search, cancel);
  out.stats.search = out.search.stats;
  ChordRefinement chords = refineConcaveChords(domains, camera, contourFaces(surface, out.search),
                                               options.chords, out.search);
  for (int face : out.search.loopFaces) {
    chords.interiorRates[face] =
        std::max(chords.interiorRates[face], loopRate(domains, camera, face));
  }
  out.stats.refinedEdges = chords.refinedEdges;
  out.stats.refinedFaces = chords.refinedFaces;

  const int faceCount = surface.faceCount();
  std::vector<FacePiece> pieces(faceCount);
  parallelFor(faceCount, 32, [&](size_t begin, size_t end) {
    for (size_t f = begin; f < end; ++f) {
      if ((f & 63) == 0) cancel.check();
      if (!surface.hasLimit(static_cast<int>(f))) continue;
      FacePiece& piece = pieces[f];
      const int face = static_cast<int>(f);
      piece = buildFace(domains, camera, out.search, chords, options, face);
      // Again after buildFace: it culls only the faces it splits, and before the splits.
      if (options.cullHidden) piece.culled += cullHidden(domains, camera, face, piece);
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
    // (u, v) leave the method in Bfr's parameterisation, as every other mesh has them.
    std::vector<Vec2> surfaceUVs;
    for (const FacePoint& p : piece.points) surfaceUVs.push_back(domains.toSurface(f, p.uv));
    for (const std::array<int, 3>& t : piece.triangles) {
      for (int k : t) {
        mesh.indices.push_back(first + static_cast<uint32_t>(k));
        const Vec2& uv = surfaceUVs[k];
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
    out.stats.interiorSplits += piece.splits;
    out.stats.trianglesCulled += piece.culled;
    out.stats.unresolvedSamples += piece.unresolved;
    if (piece.odd) ++out.stats.oddFaces;
    for (ContourCurve& c : piece.curves) {
      for (FacePoint& p : c.points) p.uv = domains.toSurface(f, p.uv);
      out.curves.push_back(std::move(c));
    }
  }
  out.stats.trianglesDrawn = mesh.triangleCount();
  return out;
}

}  // namespace limn::render::silhouette
