// The exact reference of an implicit surface F = iso: rays intersected with the isosurface
// itself, inside Embree's traversal.
//
// The scene is one Embree user geometry whose primitives are the support boxes of the field's
// positive primitives (every point with F >= iso lies in one of them). For a ray and a box, the
// intersect callback walks the ray's stretch inside the box with steps the field's local
// Lipschitz bound makes safe (|F - iso| / L can be crossed without meeting a root), brackets
// the first sign change and refines it; the stretch is searched only when F < iso where the ray
// enters the box (otherwise an earlier box holds the ray's first crossing). Embree keeps the
// closest hit over all boxes. Hits are then refined again in double precision on the pixel's own
// ray (Embree's rays are single precision) to 1e-9 of the domain's diagonal, and shaded with the
// gradient's normal, through the same passes and shading as the limit-surface reference.
// Steps never go below the lesser of 1e-4 of the diagonal and a quarter of a pixel's footprint
// at the ray's distance (so a search near a grazing or badly bounded surface ends): two crossings
// closer than that along one ray (a sliver thinner than a quarter pixel) can be stepped over.
// Overlapping boxes are merged, so a ray marches each stretch once.
#pragma once

#include "render/core/camera.h"
#include "render/core/cancel.h"
#include "render/core/passes.h"
#include "render/implicit/field.h"
#include "render/oracle/reference.h"

namespace limn::render::oracle {

// As renderReference (reference.h), for a field: the passes, the supersampled mask where it can
// differ from the pixel's coverage (and where options.maskHint says), the outline when asked.
// stats.triangles is 0; stats.newtonMs is the double-precision refinement and shading.
ReferenceResult renderImplicitReference(const implicit::Field& field, const Camera& camera,
                                        const PassSelection& passes, const CancelToken& cancel,
                                        const ReferenceOptions& options = {});

}  // namespace limn::render::oracle
