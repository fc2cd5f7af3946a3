// The dense tessellation the reference casts its rays against.
//
// Rays hit triangles first and are then moved onto the limit surface, so inside the outline the
// triangles only need to be fine enough for Newton to start close; at the outline, though, the
// triangles decide coverage, and their chord error is the reference mask's error. So faces that
// carry an outline get a density (AdaptiveOptions::density) that brings the chord error there
// below kOutlineChordErrorPx output pixels; the rest is diced at kReferenceDicingRate.
//
// A face carries an outline when the facing of its limit surface, g = dot(n, view), changes
// sign over a grid of samples (or comes within the normal's variation of zero), when it borders
// a boundary or a hole, or when it borders a crease across which facing changes. Its density
// comes from the curvature estimated from the samples: a chord of length s on a curve of radius
// R deviates by s^2 / (8 R), so s = sqrt(8 e R) meets error e. The adaptive tessellator measures
// edges by their projected length, which at the silhouette is foreshortened (an edge running
// towards the viewer looks short but is curved); the density is computed against that measure,
// per edge, so every edge of an outline face gets at least the segments its true length needs.
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
// Segments per edge at most (Bfr tessellation rate).
inline constexpr int kReferenceMaxEdgeRate = 512;

struct ReferenceTessellation {
  tessellate::TriangleMesh mesh;
  size_t outlineFaces = 0;  // faces tessellated with an outline density
};

// `camera` is the output camera (not the supersampled one).
ReferenceTessellation tessellateForReference(const subdiv::LimitSurface& surface,
                                             const Camera& camera, const CancelToken& cancel);

// The per-face densities used above (exposed for tests): 1 away from outlines.
std::vector<double> outlineDensities(const subdiv::LimitSurface& surface, const Camera& camera);

}  // namespace limn::render::oracle
