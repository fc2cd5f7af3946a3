// SurfaceHit: a ray's exact intersection with the limit surface, found from the hit of the same
// ray on a dense tessellation.
//
// The tessellation hit gives the face and, by interpolating the triangle's corner (u, v), a
// starting point within the chord error of the answer; Newton's method on
//   F(u, v, t) = P(u, v) - (o + t d) = 0,  Jacobian [Pu  Pv  -d],
// then converges in a few steps. (u, v) stays in the face's parameter domain: for faces split
// into quad sub-faces (n-gons of Catmull-Clark meshes) a step that crosses one of the spokes
// between sub-faces continues in the neighbouring sub-face, whose coordinates are rotated by a
// quarter turn; a step that leaves the face altogether is a failure, and so are steps that do not
// converge (grazing rays at the silhouette, where the tessellation may be hit and the surface
// missed). A failed refinement keeps the tessellation's hit: its ray distance and the limit normal
// at the interpolated (u, v).
#pragma once

#include <cstdint>

#include "render/oracle/ray_caster.h"
#include "render/subdiv/limit_surface.h"
#include "render/tessellate/triangle_mesh.h"

namespace limn::render::oracle {

struct SurfaceHit {
  bool refined = false;  // Newton converged inside the face
  int face = -1;
  Vec2 uv;
  double t = 0;  // along the PixelRay
  Vec3 position;
  Vec3 normal;  // the limit normal at (face, uv): unit, oriented by the face winding
  int iterations = 0;
};

// The face and (u, v) where a ray hit triangle `triangle` of `mesh` at Embree's barycentric
// (bu, bv). For sub-faced n-gons the corners (which may lie in two neighbouring sub-faces) are
// first written in one sub-face's coordinates. False when the point falls outside the face.
bool triangleHitUV(const subdiv::LimitSurface& surface, const tessellate::TriangleMesh& mesh,
                   uint32_t triangle, float bu, float bv, int* face, Vec2* uv);

// The tessellation's hit itself, unrefined: the ray's point at t, the limit normal at (face, uv).
SurfaceHit unrefinedHit(const subdiv::LimitSurface& surface, int face, Vec2 uv, const PixelRay& ray,
                        double t);

// Refines a hit at (face, uv0, t0) of `ray`; converged when |F| < tolerance (world units).
SurfaceHit refineHit(const subdiv::LimitSurface& surface, int face, Vec2 uv0, const PixelRay& ray,
                     double t0, double tolerance);

}  // namespace limn::render::oracle
