// The silhouette method: a coarse (pre-subdivided) control mesh drawn with its vertices on the
// limit surface, where only the faces the contour passes through are re-triangulated through
// contour curves found on the limit surface itself. The outline then follows the exact limit
// contour while the triangle count stays near the coarse mesh's.
//
//   searchContour   edges -> edge points where g = dot(n, p - eye) changes sign
//   faceCurves      per face: crossings paired, curves sampled ("pn" or "exact")
//   refineConcaveChords  one ring out: points where a chord would lie outside the surface
//   triangulateFace per face with edge points: regions cut by the curves, Delaunay in (u, v)
// Faces with no edge point keep their corners: quads as two triangles, triangles as one.
#pragma once

#include <vector>

#include "render/core/camera.h"
#include "render/core/cancel.h"
#include "render/silhouette/chord_refinement.h"
#include "render/silhouette/contour_search.h"
#include "render/silhouette/face_contour.h"
#include "render/subdiv/limit_surface.h"
#include "render/tessellate/triangle_mesh.h"

namespace limn::render::silhouette {

struct SilhouetteOptions {
  SearchOptions search;
  CurveOptions curves;
  ChordOptions chords;
  size_t maxTriangles = 8'000'000;
  // Leave out triangles that cannot be seen: on closed surfaces those facing away from the eye
  // (drawn, their chords can show through along inner contours), on any surface the back
  // sheet's triangles cornered on the contour alone (their chords span a concave outline).
  bool cullHidden = true;
};

// One contour curve inside one face, endpoints included (both are edge points).
struct ContourCurve {
  int face = -1;
  int fromEdge = -1, fromPoint = -1;  // ContourSearch::edgePoints[fromEdge][fromPoint]
  int toEdge = -1, toPoint = -1;
  std::vector<FacePoint> points;  // (u, v) in Bfr's parameterisation of the face
};

struct SilhouetteStats {
  int presubdivisionLevels = 0;  // refinement steps before the method ran (set by its caller)
  SearchStats search;
  size_t contourFaces = 0;    // faces holding at least one contour curve
  size_t correctedFaces = 0;  // faces re-triangulated (contour faces and their edge neighbours)
  size_t refinedEdges = 0;    // edges given points because their chord lay outside (concave)
  size_t refinedFaces = 0;    // ring faces given interior points for the same reason
  size_t interiorSplits = 0;  // contour-face edges split because their chord lay outside
  size_t trianglesAdded = 0;  // triangles drawn beyond the coarse mesh's
  size_t trianglesDrawn = 0;
  size_t trianglesCulled = 0;  // left out as hidden (SilhouetteOptions::cullHidden)
  size_t curveSamples = 0;
  size_t unresolvedSamples = 0;  // exact samples that found no root (left on the straight line)
  size_t oddFaces = 0;           // faces with an odd crossing count (drawn without a curve)
};

struct SilhouetteMesh {
  tessellate::TriangleMesh mesh;
  ContourSearch search;
  std::vector<ContourCurve> curves;
  std::vector<bool> corrected;  // per face
  SilhouetteStats stats;
};

SilhouetteMesh buildSilhouetteMesh(const subdiv::LimitSurface& surface, const Camera& camera,
                                   const SilhouetteOptions& options, const CancelToken& cancel);

}  // namespace limn::render::silhouette
