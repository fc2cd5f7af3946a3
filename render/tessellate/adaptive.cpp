// Adaptive tessellation of the limit surface for one camera.
//
// 1. Each face is probed at its corners and edge midpoints (Bfr's rate-2 boundary points):
//    faces entirely outside the view, or facing away on a closed surface and not near edge-on
//    (kCullMarginCosine), are culled to the smallest rate.
// 2. Every edge gets one rate: the largest its faces ask for, a face asking for its edge's
//    projected length (along the limit curve's corner-midpoint-corner polyline) divided by the
//    dicing rate, or its unforeshortened length where the face holds a silhouette
//    (unforeshortenedPixels), and crowdedContourScale times finer where its contour runs
//    close to another part's (contour_proximity.h); callers may raise any edge's count
//    (AdaptiveOptions::minSegments).
// 3. The triangles those rates make are counted (Bfr::Tessellation, nothing evaluated) and
//    checked against maxTriangles before any memory is spent on them.
// 4. Faces are tessellated independently (Bfr::Tessellation with those edge rates) and
//    evaluated in parallel.
// 5. Assembly shares the points of each edge between its faces, so the mesh is watertight by
//    construction; a shared point gets a second vertex (same position) only where the faces'
//    normals disagree, as across an infinitely sharp crease.
#include <opensubdiv/bfr/tessellation.h>

#include <cmath>
#include <numbers>
#include <string>

#include "render/core/error.h"
#include "render/core/parallel.h"
#include "render/tessellate/contour_proximity.h"
#include "render/tessellate/tessellate.h"

namespace limn::render::tessellate {

namespace Bfr = OpenSubdiv::Bfr;
namespace Far = OpenSubdiv::Far;

namespace {

// A face that faces away from the eye on a closed surface is hidden, so it is culled to one
// segment per edge; but its chords are not hidden. Where the surface is concave (a pawn's neck
// seen from the side) the chord of a face just behind the silhouette lies outside the surface
// and pokes past the outline, by up to the face's sag. That happens only when the face comes
// within about half its own turn of normal of edge-on (a face turning by phi with radius R sags
// by R phi^2 / 8, while its point nearest edge-on at angle theta lies R theta^2 / 2 inside the
// outline), so a face is culled only when every probe sees it further from edge-on than half
// its turn, plus a margin. The pawn at 1024^2 was 1.04 px off at any dicing rate before; this
// alone made it 0.03 px at dicingRate 1, for a third more triangles.
constexpr double kCullMarginCosine = 0.02;

struct FaceProbe {
  bool culled = true;
  std::vector<double> edgePixels;     // projected length of each edge
  std::vector<ContourPiece> contour;  // where the probes change facing, in the image
};

struct FacePatch {
  std::vector<double> coords;  // (u, v) pairs: boundary points first, then interior
  std::vector<int> facets;     // triangles, indices into coords
  std::vector<subdiv::LimitSample> samples;
  int boundaryCount = 0;
};

FaceProbe probeFace(const subdiv::LimitSurface& surface, int face, const Camera& camera,
                    int hiddenSide) {
  FaceProbe probe;
  Bfr::Parameterization param = surface.parameterization(face);
  const int n = param.GetFaceSize();
  Bfr::Tessellation rate2(param, 2);
  std::vector<double> uv(2 * rate2.GetNumBoundaryCoords());
  rate2.GetBoundaryCoords(uv.data());  // corner 0, mid of edge 0, corner 1, ...

  std::vector<Vec3> pixel(2 * n), position(2 * n);
  std::vector<double> facingOf(2 * n);
  const double margin = 0.05 * std::max(camera.width(), camera.height());
  // Facing the eye or away by the limit normal, which follows the winding.
  bool anyInFront = false, anyTowards = false, anyAway = false;
  double nearestEdgeOn = 1;  // the smallest |cosine| between a probe's normal and its view ray
  double turn = 0;           // the largest angle between the first probe's normal and another's
  Vec3 firstNormal;
  double minX = 1e300, maxX = -1e300, minY = 1e300, maxY = -1e300;
  for (int i = 0; i < 2 * n; ++i) {
    subdiv::LimitSample s = surface.evaluate(face, uv[2 * i], uv[2 * i + 1]);
    Vec3 view = camera.viewVector(s.position);
    const double facing = dot(s.normal, view) / std::max(length(view), 1e-300);
    facingOf[i] = facing;
    if (facing < 1e-3) anyTowards = true;
    if (facing > -1e-3) anyAway = true;
    nearestEdgeOn = std::min(nearestEdgeOn, std::abs(facing));
    if (i == 0) firstNormal = s.normal;
    turn = std::max(turn,
                    std::atan2(length(cross(firstNormal, s.normal)), dot(firstNormal, s.normal)));
    position[i] = s.position;
    pixel[i] = camera.project(s.position);
    bool inFront = camera.projection() == Projection::Orthographic || pixel[i].z > 0;
    if (inFront) {
      anyInFront = true;
      minX = std::min(minX, pixel[i].x);
      maxX = std::max(maxX, pixel[i].x);
      minY = std::min(minY, pixel[i].y);
      maxY = std::max(maxY, pixel[i].y);
    }
  }
  bool partlyBehind = false;
  for (const Vec3& p : pixel) {
    if (camera.projection() == Projection::Perspective && p.z <= camera.nearPlane()) {
      partlyBehind = true;
    }
  }
  bool outside =
      !anyInFront || (!partlyBehind && (maxX < -margin || minX > camera.width() + margin ||
                                        maxY < -margin || minY > camera.height() + margin));
  const bool nearEdgeOn =
      (anyTowards && anyAway) ||
      nearestEdgeOn < std::sin(std::min(turn / 2, std::numbers::pi / 2)) + kCullMarginCosine;
  // On a closed piece the side away from the eye is hidden; an inside-out piece's limit normals
  // point in, so its hidden side is the one they call "towards".
  const bool allHidden = hiddenSide > 0 ? !anyTowards : hiddenSide < 0 && !anyAway;
  probe.culled = outside || (allHidden && !nearEdgeOn);
  if (!probe.culled && !partlyBehind && anyTowards && anyAway) {
    std::vector<Vec2> points(2 * n);
    for (int i = 0; i < 2 * n; ++i) points[i] = {pixel[i].x, pixel[i].y};
    appendContourPieces(points, facingOf, face, probe.contour);
  }
  probe.edgePixels.resize(n);
  for (int k = 0; k < n; ++k) {
    const Vec3& a = pixel[2 * k];
    const Vec3& m = pixel[2 * k + 1];
    const Vec3& b = pixel[(2 * k + 2) % (2 * n)];
    if (partlyBehind) {
      probe.edgePixels[k] = 1e300;  // crosses the eye plane: as fine as allowed
    } else {
      probe.edgePixels[k] = std::hypot(m.x - a.x, m.y - a.y) + std::hypot(b.x - m.x, b.y - m.y);
      if (anyTowards && anyAway) {
        probe.edgePixels[k] = std::max(
            probe.edgePixels[k], unforeshortenedPixels(camera, position[2 * k], position[2 * k + 1],
                                                       position[(2 * k + 2) % (2 * n)]));
      }
    }
  }
  return probe;
}

// Per face: whether its contour comes within a pixel of another part's contour in the image
// (contour_proximity.h), faces that share a vertex being one part.
std::vector<char> facesNearAnotherContour(const subdiv::LimitSurface& surface,
                                          const std::vector<FaceProbe>& probes,
                                          const Camera& camera, const AdaptiveOptions& options) {
  const int faceCount = surface.faceCount();
  if (options.crowdedContourScale <= 1) return std::vector<char>(faceCount, 0);
  std::vector<ContourPiece> pieces;
  for (const FaceProbe& probe : probes) {
    pieces.insert(pieces.end(), probe.contour.begin(), probe.contour.end());
  }
  const Far::TopologyLevel& base = surface.baseLevel();
  auto shareAVertex = [&](int a, int b) {
    Far::ConstIndexArray va = base.GetFaceVertices(a), vb = base.GetFaceVertices(b);
    for (int i = 0; i < va.size(); ++i) {
      for (int j = 0; j < vb.size(); ++j) {
        if (va[i] == vb[j]) return true;
      }
    }
    return false;
  };
  return ownersNearAnotherContour(pieces, faceCount, kCrowdedContourPx, camera.width(),
                                  camera.height(), shareAVertex);
}

// Runs fn(face, rates) on all threads for every face with a limit surface, `rates` holding the
// face's edge rates in its edge order.
template <typename Fn>
void forEachFaceWithRates(const subdiv::LimitSurface& surface, const std::vector<int>& edgeRate,
                          size_t grain, const CancelToken& cancel, const Fn& fn) {
  const Far::TopologyLevel& base = surface.baseLevel();
  parallelFor(surface.faceCount(), grain, [&](size_t begin, size_t end) {
    cancel.check();
    std::vector<int> rates;
    for (size_t f = begin; f < end; ++f) {
      const int face = static_cast<int>(f);
      if (!surface.hasLimit(face)) continue;
      Far::ConstIndexArray edges = base.GetFaceEdges(face);
      rates.resize(edges.size());
      for (int k = 0; k < edges.size(); ++k) rates[k] = edgeRate[edges[k]];
      fn(face, rates.data());
    }
  });
}

// Bfr's tessellation of a face with these edge rates. Bfr infers a quad's inner rates as the
// means of opposite edges' rates, and (in the Bfr Debian ships) a quad one of whose inner rates
// is 1 while the other is not becomes a fan from its centre: a long thin quad with 1 segment
// across and 48 along was drawn as 98 chords from its middle, each spanning half the face (on
// the hat's crown seen from below, such fans stood 1.08 px outside the outline). Such an inner
// rate is raised to 2, which puts a row of points down the quad's middle.
Bfr::Tessellation faceTessellation(const Bfr::Parameterization& param, const int* rates) {
  const int n = param.GetFaceSize();
  if (n != 4) return Bfr::Tessellation(param, n, rates);
  int withInner[6] = {
      rates[0], rates[1], rates[2], rates[3], (rates[0] + rates[2]) / 2, (rates[1] + rates[3]) / 2};
  for (int k = 0; k < 2; ++k) {
    if (withInner[4 + k] == 1 && withInner[5 - k] > 1) withInner[4 + k] = 2;
  }
  return Bfr::Tessellation(param, 6, withInner);
}

// Triangles the faces make with these edge rates (Bfr counts them without evaluating).
size_t countTriangles(const subdiv::LimitSurface& surface, const std::vector<int>& edgeRate,
                      const CancelToken& cancel) {
  std::vector<size_t> perFace(surface.faceCount(), 0);
  forEachFaceWithRates(surface, edgeRate, 256, cancel, [&](int face, const int* rates) {
    Bfr::Parameterization param = surface.parameterization(face);
    perFace[face] = faceTessellation(param, rates).GetNumFacets();
  });
  size_t total = 0;
  for (size_t n : perFace) total += n;
  return total;
}

// Throws when the rates make more than maxTriangles, or with fitToBudget scales them down by
// the square root of the excess (triangles grow as the square of the rates) until they fit.
void keepToTriangleBudget(const subdiv::LimitSurface& surface, const AdaptiveOptions& options,
                          std::vector<int>& edgeRate, const CancelToken& cancel) {
  size_t triangles = countTriangles(surface, edgeRate, cancel);
  double scaled = 1;
  while (triangles > options.maxTriangles) {
    if (!options.fitToBudget) {
      throw InputError(
          InputError::Kind::LimitExceeded, "maxTriangles",
          std::string(options.stage) + " tessellation would make " + std::to_string(triangles) +
              " triangles: exceeds limit maxTriangles " + std::to_string(options.maxTriangles) +
              (*options.remedy ? std::string(" (") + options.remedy + ")" : std::string()));
    }
    cancel.check();
    double factor = std::sqrt(static_cast<double>(options.maxTriangles) / triangles) * 0.95;
    bool changed = false;
    for (int& rate : edgeRate) {
      int lower = std::max(options.minEdgeRate, static_cast<int>(std::floor(rate * factor)));
      changed |= lower != rate;
      rate = lower;
    }
    scaled *= factor;
    if (!changed) break;  // every edge at its smallest rate: the mesh itself is the budget
    triangles = countTriangles(surface, edgeRate, cancel);
  }
  if (options.ratesScaled) *options.ratesScaled = scaled;
}

FacePatch tessellateFace(const subdiv::LimitSurface& surface, int face, const int* rates) {
  FacePatch patch;
  Bfr::Parameterization param = surface.parameterization(face);
  Bfr::Tessellation tess = faceTessellation(param, rates);
  patch.boundaryCount = tess.GetNumBoundaryCoords();
  patch.coords.resize(2 * tess.GetNumCoords());
  tess.GetCoords(patch.coords.data());
  patch.facets.resize(3 * tess.GetNumFacets());
  tess.GetFacets(patch.facets.data());
  patch.samples.resize(tess.GetNumCoords());
  for (int i = 0; i < tess.GetNumCoords(); ++i) {
    patch.samples[i] = surface.evaluate(face, patch.coords[2 * i], patch.coords[2 * i + 1]);
  }
  return patch;
}

// Vertices of the output mesh, shared per surface point and split only where normals differ.
class VertexPool {
 public:
  VertexPool(TriangleMesh& mesh, size_t pointCount) : mesh_(mesh), first_(pointCount, -1) {}

  uint32_t vertexFor(size_t point, const subdiv::LimitSample& sample) {
    const double kSameNormal = std::cos(1.0 * 3.14159265358979 / 180.0);
    int v = first_[point];
    Vec3f position(sample.position);
    if (v >= 0) {
      position = mesh_.positions[v];  // the first face's position: exactly shared
      for (int w = v; w >= 0; w = next_[w]) {
        if (dot(mesh_.normals[w].toDouble(), sample.normal) >= kSameNormal) return w;
      }
    }
    int created = static_cast<int>(mesh_.positions.size());
    mesh_.positions.push_back(position);
    mesh_.normals.emplace_back(sample.normal);
    next_.push_back(-1);
    if (v < 0) {
      first_[point] = created;
    } else {  // append to the chain of vertices at this point
      int last = v;
      while (next_[last] >= 0) last = next_[last];
      next_[last] = created;
    }
    return static_cast<uint32_t>(created);
  }

  uint32_t uniqueVertex(const subdiv::LimitSample& sample) {
    mesh_.positions.emplace_back(sample.position);
    mesh_.normals.emplace_back(sample.normal);
    next_.push_back(-1);
    return static_cast<uint32_t>(mesh_.positions.size() - 1);
  }

 private:
  TriangleMesh& mesh_;
  std::vector<int> first_;  // per shared point: its first vertex
  std::vector<int> next_;   // per vertex: the next vertex at the same point, or -1
};

}  // namespace

TriangleMesh tessellateAdaptive(const subdiv::LimitSurface& surface, const Camera& camera,
                                const AdaptiveOptions& options, const CancelToken& cancel) {
  const Far::TopologyLevel& base = surface.baseLevel();
  const int faceCount = surface.faceCount();

  // 1. Probe faces.
  std::vector<FaceProbe> probes(faceCount);
  parallelFor(faceCount, 64, [&](size_t begin, size_t end) {
    cancel.check();
    for (size_t f = begin; f < end; ++f) {
      if (surface.hasLimit(static_cast<int>(f))) {
        probes[f] = probeFace(surface, static_cast<int>(f), camera,
                              surface.hiddenSide(static_cast<int>(f)));
      }
    }
  });

  // 2. One rate per edge.
  const std::vector<char> crowded = facesNearAnotherContour(surface, probes, camera, options);
  std::vector<int> edgeRate(base.GetNumEdges(), options.minEdgeRate);
  for (int f = 0; f < faceCount; ++f) {
    if (!surface.hasLimit(f)) continue;
    Far::ConstIndexArray edges = base.GetFaceEdges(f);
    const double dicingRate =
        crowded[f] ? options.dicingRate / options.crowdedContourScale : options.dicingRate;
    for (int k = 0; k < edges.size(); ++k) {
      int rate = options.minEdgeRate;
      if (!probes[f].culled) {
        double segments = std::ceil(probes[f].edgePixels[k] / dicingRate);
        rate = static_cast<int>(std::clamp(segments, static_cast<double>(options.minEdgeRate),
                                           static_cast<double>(options.maxEdgeRate)));
      }
      edgeRate[edges[k]] = std::max(edgeRate[edges[k]], rate);
    }
  }
  if (options.minSegments) {
    for (int e = 0; e < base.GetNumEdges(); ++e) {
      edgeRate[e] = std::clamp(options.minSegments(e), edgeRate[e], options.maxEdgeRate);
    }
  }

  // 3. Count the triangles those rates make, before evaluating anything, and keep to the budget.
  keepToTriangleBudget(surface, options, edgeRate, cancel);

  // 4. Tessellate and evaluate every face.
  std::vector<FacePatch> patches(faceCount);
  forEachFaceWithRates(surface, edgeRate, 16, cancel, [&](int face, const int* rates) {
    patches[face] = tessellateFace(surface, face, rates);
  });
  size_t triangles = 0;
  for (const FacePatch& p : patches) triangles += p.facets.size() / 3;
  cancel.check();

  // 5. Assemble. Shared points: mesh vertices first, then each edge's interior points.
  std::vector<size_t> edgeFirstPoint(base.GetNumEdges());
  size_t pointCount = static_cast<size_t>(surface.mesh().vertexCount());
  for (int e = 0; e < base.GetNumEdges(); ++e) {
    edgeFirstPoint[e] = pointCount;
    pointCount += edgeRate[e] - 1;
  }
  TriangleMesh out;
  out.indices.reserve(3 * triangles);
  out.triangleFaces.reserve(triangles);
  out.cornerUVs.reserve(3 * triangles);
  VertexPool pool(out, pointCount);
  std::vector<uint32_t> vertexOf;
  for (int f = 0; f < faceCount; ++f) {
    if (!surface.hasLimit(f)) continue;
    const FacePatch& patch = patches[f];
    Far::ConstIndexArray faceVerts = base.GetFaceVertices(f);
    Far::ConstIndexArray edges = base.GetFaceEdges(f);
    vertexOf.resize(patch.samples.size());
    int coord = 0;
    for (int k = 0; k < edges.size(); ++k) {
      vertexOf[coord] = pool.vertexFor(faceVerts[k], patch.samples[coord]);
      ++coord;
      const int rate = edgeRate[edges[k]];
      const bool forward = base.GetEdgeVertices(edges[k])[0] == faceVerts[k];
      for (int i = 1; i < rate; ++i, ++coord) {
        size_t point = edgeFirstPoint[edges[k]] + (forward ? i - 1 : rate - 1 - i);
        vertexOf[coord] = pool.vertexFor(point, patch.samples[coord]);
      }
    }
    for (size_t i = coord; i < patch.samples.size(); ++i) {
      vertexOf[i] = pool.uniqueVertex(patch.samples[i]);
    }
    for (size_t t = 0; t < patch.facets.size(); t += 3) {
      out.triangleFaces.push_back(f);
      for (int c = 0; c < 3; ++c) {
        int i = patch.facets[t + c];
        out.indices.push_back(vertexOf[i]);
        out.cornerUVs.push_back(
            {static_cast<float>(patch.coords[2 * i]), static_cast<float>(patch.coords[2 * i + 1])});
      }
    }
  }
  return out;
}

}  // namespace limn::render::tessellate
