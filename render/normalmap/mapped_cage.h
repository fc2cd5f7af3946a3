// The control cage as a TriangleMesh ready for Shading::NormalMap: the coarse geometry of
// tessellateCoarse, shaded with the limit surface's normals from a NormalAtlas.
#pragma once

#include "render/normalmap/normal_atlas.h"
#include "render/subdiv/limit_surface.h"
#include "render/tessellate/triangle_mesh.h"

namespace limn::render::normalmap {

// Every face with a chart becomes triangles with their own vertices (texture coordinates
// differ from face to face): a quad two triangles fanned from corner 0 and a triangle of Loop
// or Bilinear one, as tessellateCoarse draws them; a face split into sub-faces (Catmull-Clark
// triangles and n-gons) one quad per sub-face: corner k, the midpoint of edge k, the centroid
// of the corners, the midpoint of edge k - 1, so that no triangle spans two charts. Positions
// are the control points (and those midpoints and centroids); normals and limitPositions are the
// limit surface's at each vertex's parameter; texcoords come from `atlas`, whose image becomes
// normalMap; lines are the polygon edges. Faces without a limit (holes) are left out.
tessellate::TriangleMesh mappedCage(const subdiv::LimitSurface& surface, const NormalAtlas& atlas);

}  // namespace limn::render::normalmap
