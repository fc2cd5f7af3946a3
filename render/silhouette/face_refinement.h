// Concave contour faces: the triangles ear-clipped between a face's boundary and its contour
// curves are chords of the surface; where the surface is concave across them (the inside of
// a torus's hole) a chord lies outside it and can poke past the exact outline. Interior edges
// whose chord lies outside the surface by more than a tolerance (projected) are split at their
// (u, v) midpoint, moved onto the limit surface, until none is left or a split budget is spent.
// Splitting an interior edge changes only the two triangles beside it, both inside the face, so
// the face's boundary (shared with neighbours) and its contour curves are never touched.
#pragma once

#include <array>
#include <vector>

#include "render/core/camera.h"
#include "render/silhouette/face_contour.h"
#include "render/subdiv/limit_surface.h"

namespace limn::render::silhouette {

// `points`/`triangles` as built for one face; the first `boundaryCount` points are its
// boundary in order, and `lockedChains` lists point sequences (contour curves, endpoints
// included) whose consecutive pairs must stay edges. Returns the number of splits made.
int refineFaceTriangles(const FaceDomains& domains, const Camera& camera, int face,
                        int boundaryCount, const std::vector<std::vector<int>>& lockedChains,
                        double tolerancePx, int maxSplits, std::vector<FacePoint>& points,
                        std::vector<std::array<int, 3>>& triangles);

}  // namespace limn::render::silhouette
