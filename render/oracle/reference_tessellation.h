// The dense tessellation the reference casts its rays against.
//
// Rays hit triangles first and are then moved onto the limit surface, so inside the outline the
// triangles only need to be fine enough for Newton to start close; at the outline, though, the
// triangles decide coverage, and their chord error is the reference mask's error. So the edges of
// faces that carry an outline get enough segments (AdaptiveOptions::minSegments) to bring the
// chord error there below kOutlineChordErrorPx output pixels; the rest is diced at
// kReferenceDicingRate.
//
// A face carries an outline when the facing of its limit surface, g = dot(n, view), changes
// sign over a grid of samples (or comes within the normal's variation of zero), when it borders
// a boundary or a hole, or when it borders a crease across which facing changes (see
// surface_probe.h for the samples and the segment counts). The segments are given per edge
// (AdaptiveOptions::minSegments), from 3D lengths: a per-face density on the tessellator's
// projected lengths would refine a silhouette face's transverse edges as much as its
// foreshortened ones, 50 times more triangles on the corpus torus at 1024^2.
#pragma once

#include "render/core/camera.h"
#include "render/core/cancel.h"
#include "render/subdiv/limit_surface.h"
#include "render/tessellate/triangle_mesh.h"

namespace limn::render::oracle {

// Target edge length away from outlines, in output pixels.
inline constexpr double kReferenceDicingRate = 2.0;
// Target chord error of outline faces, in output pixels: an eighth of a supersampled pixel at
// S = 8 is 0.016; this keeps below that with margin.
inline constexpr double kOutlineChordErrorPx = 0.01;
// The edge length away from outlines may grow to this when the budget needs it (fitToBudget).
inline constexpr double kReferenceMaxDicingRate = 16.0;
// Segments per edge at most (Bfr tessellation rate).
inline constexpr int kReferenceMaxEdgeRate = 512;
// Triangles the reference aims to stay within (estimated before tessellating; Embree needs
// roughly 100 bytes per triangle). Beyond it the dicing rate away from outlines is raised first,
// then the outline error, and the caller is told (ReferenceStats::accuracyPx).
inline constexpr double kReferenceTriangleBudget = 3e6;

struct ReferenceTessellation {
  tessellate::TriangleMesh mesh;
  size_t outlineFaces = 0;    // faces whose edges were refined for an outline
  double outlineErrorPx = 0;  // the chord error its outline edges keep to (output pixels)
  double dicingRate = 0;      // the edge length aimed for elsewhere (output pixels)
  // Per control face: it borders a boundary, a hole or a face without limit surface, so its
  // outline can run along its edges whatever the facing (the reference's mask refines there).
  std::vector<char> borderFaces;
  // 1, or the factor every edge rate was scaled by to stay within 4x the budget when the
  // estimate fell short (the outline error grows as its inverse square).
  double ratesScaled = 1;
};

// `camera` is the output camera (not the supersampled one); `triangleBudget` as
// kReferenceTriangleBudget (the server's limits.maxReferenceTriangles).
ReferenceTessellation tessellateForReference(const subdiv::LimitSurface& surface,
                                             const Camera& camera, const CancelToken& cancel,
                                             double triangleBudget = kReferenceTriangleBudget);

}  // namespace limn::render::oracle
