// The parameter domain the silhouette method works in, face by face. Quads and triangles use
// Bfr's own (the unit square, the unit triangle). Other faces of Catmull-Clark meshes have a Bfr
// domain of n separate quad tiles (Bfr::Parameterization's sub-faces), in which the face's
// boundary is no polygon at all; for them the method works in a regular n-gon instead, cut into
// n kites (corner k, the midpoints of its two edges, the centre), each mapped bilinearly onto
// sub-face k in its normalised coordinates (origin at corner k, u towards the midpoint of edge
// k, v towards that of edge k-1: the children of one Catmull-Clark step). The map is continuous
// across kites, so such a face is one convex polygon to the contour curves, the triangulation
// and the splits, and needs no pre-subdivision. toSurface() converts back to Bfr's (u, v) for
// everything outside the method (triangle corners, polylines, metrics).
#pragma once

#include <vector>

#include "render/core/vec.h"
#include "render/subdiv/limit_surface.h"

namespace limn::render::silhouette {

class FaceDomains {
 public:
  explicit FaceDomains(const subdiv::LimitSurface& surface);

  const subdiv::LimitSurface& surface() const { return surface_; }
  int size(int face) const { return sizes_[face]; }
  bool isTriangle(int face) const { return kind_[face] == Kind::Triangle; }

  Vec2 corner(int face, int k) const;
  Vec2 center(int face) const;
  // The point at `t` along the face's k-th edge (corner k to corner k + 1).
  Vec2 alongEdge(int face, int k, double t) const;
  // Inside the face's domain (up to a small tolerance).
  bool contains(int face, const Vec2& uv) const;
  // True when both points lie on one side of the domain's boundary.
  bool onOneSide(int face, const Vec2& a, const Vec2& b) const;

  // Bfr's (u, v) of a point of the domain.
  Vec2 toSurface(int face, const Vec2& uv) const;
  subdiv::LimitSample evaluate(int face, const Vec2& uv) const;
  Vec3 position(int face, const Vec2& uv) const { return evaluate(face, uv).position; }

 private:
  enum class Kind : unsigned char { Quad, Triangle, Polygon };
  const subdiv::LimitSurface& surface_;
  std::vector<Kind> kind_;
  std::vector<int> sizes_;
};

}  // namespace limn::render::silhouette
