// The exact reference: Embree ray casting of the limit surface, used as the oracle every
// approximation is measured against.
//
// Rays are cast against a dense triangle tessellation of the limit surface (finer at outlines,
// so the outline's chord error is about 0.01 output pixels: reference_tessellation.h); every hit
// is then moved onto the true surface at its (face, u, v) by Newton steps on the Bfr surface,
// so depth and normals are exact to about 1e-9 of the model size (surface_hit.h). Shading uses
// the limit normal and render/core/shading.h. For Catmull-Clark meshes a second, independent
// path ray-casts Embree's own subdivision geometry, and the two masks' disagreement is reported.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "render/core/camera.h"
#include "render/core/cancel.h"
#include "render/core/image.h"
#include "render/core/passes.h"
#include "render/subdiv/limit_surface.h"

namespace limn::render::oracle {

struct ReferenceStats {
  size_t triangles = 0;        // of the dense tessellation
  size_t raysCast = 0;
  size_t newtonFailures = 0;   // hits whose refinement did not converge (kept unrefined)
  double tessellateMs = 0, bvhMs = 0, traceMs = 0;
  size_t outlineFaces = 0;     // faces tessellated finely because they carry an outline
  double outlineErrorPx = 0;   // chord error aimed for at the outline, output pixels
  size_t hits = 0;             // output pixels covered
  double newtonMs = 0;         // refinement and shading of the hits (traceMs: primary rays only)
  double maskMs = 0;           // the supersampled mask's rays
};

struct ReferenceResult {
  ImageSet images;
  ReferenceStats stats;
  std::vector<std::string> warnings;
};

// `passes.supersample` > 0 also fills the supersampled mask. Uses all hardware threads through
// TBB (Embree's), and checks `cancel` between rows of tiles.
//
// Passes follow the rasteriser's conventions: color RGBA (alpha 1 where covered; empty pixels
// are shading::kBackground with alpha 0), mask 1/0, depth linear (0 = empty), normal the unit
// limit normal as oriented by the face winding (not flipped towards the viewer; 0 = empty).
// The wireframe pass of the reference is its color pass: the limit surface has no edges to draw
// (a warning says so). Rays are clipped to the camera's [near, far] like the rasteriser's
// triangles. The supersampled mask is the dense tessellation's coverage at camera.scaled(S).
ReferenceResult renderReference(const subdiv::LimitSurface& surface, const Camera& camera,
                                const PassSelection& passes, const CancelToken& cancel);

// The independent check (Catmull-Clark only): Embree's RTC_GEOMETRY_TYPE_SUBDIVISION with the
// mesh's creases and corners, cast at `camera` (pass the supersampled one); returns its coverage
// mask, or nothing with a reason in `whyNot` where Embree cannot represent the surface as
// OpenSubdiv defines it: Loop or bilinear schemes, Chaikin creases, smooth triangle subdivision,
// faces over 15 vertices, non-manifold topology, and two crease configurations where Embree's
// rules were measured to differ from Far's limit by 2-15% of the model size (creases of
// different sharpness meeting at a vertex with one of them semi-sharp; semi-sharp corners).
// Holes and the faces boundary None removes stay in Embree's mesh (they support their
// neighbours, as in OpenSubdiv) and are skipped by a filter; boundary modes map to Embree's
// smooth boundary or pinned corners. Embree's grid is uniform over the mesh, sized from the
// chord error, and zero-width cracks between its patches are closed by re-casting. Measured
// agreement with the reference on the corpus: at most one supersampled pixel apart, mean
// 0.0002-0.004 output px; Embree is off by about 3e-4 of the model size near infinitely sharp
// crease ends and cuts infinitely sharp corner tips short by a pixel or two.
std::optional<Image> embreeSubdivisionMask(const subdiv::LimitSurface& surface,
                                           const Camera& camera, const CancelToken& cancel,
                                           std::string* whyNot);

}  // namespace limn::render::oracle
