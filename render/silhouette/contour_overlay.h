// The "contours" picture of the silhouette method: what it searched and what it found, as
// lines over the shaded surface. Base edges are coloured by the facing of their ends (green:
// both front, blue: both back, yellow: a sign change), the triangles of re-triangulated faces
// are orange, and the contour curves red, drawn last so they stay on top.
#pragma once

#include <string>

#include "render/core/overlay.h"
#include "render/silhouette/silhouette_mesh.h"

namespace limn::render::silhouette {

LineOverlay contourOverlay(const subdiv::LimitSurface& surface, const SilhouetteMesh& built,
                           const std::string& pass);

}  // namespace limn::render::silhouette
