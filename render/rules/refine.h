// limn's own uniform subdivision: one level of a mesh refined by the classic rules, written
// from the papers and checked against OpenSubdiv (tests/unit/rules_test.cpp), independent of it.
//
//   Method::Masks     Catmull-Clark (Catmull & Clark 1978) or Loop (Loop 1987) as stencils
//                     ("masks") over each new point's neighbourhood, with OpenSubdiv's boundary,
//                     crease, corner and semi-sharp rules (sharpness.h), both crease methods
//                     and Catmull-Clark's "smooth triangles" option.
//   Method::Factored  Catmull-Clark as Warren & Schaefer's factored form: a linear stage
//                     (edge midpoints, face centroids, n-gons split into n quads), an averaging
//                     stage (each vertex becomes the mean of the centroids of its quads) and a
//                     correction p^ + (4/n)(p - p^) at vertices of valence n. It equals the masks
//                     on quad meshes; on the first step it differs at the points of smooth edges
//                     next to a non-quad face (their quads' centroids are not the mask's). Sharp
//                     features use the factored curve rule (the linear stage then two averages
//                     along the crease, i.e. 1/8 6/8 1/8 and midpoints), which equals the masks
//                     for boundaries, infinitely sharp creases, darts and corners; semi-sharp
//                     sharpness and the smooth-triangle rule have no factored form and are
//                     refused.
//
// Vertex order of a refined level, as OpenSubdiv's Far orders a uniform refinement with its
// default options: first the children of the parent's vertices (same order), then, for
// Catmull-Clark, the points of the parent's faces, then the points of its edges. Edges: first
// the new edges inside each face (in face order: face point to edge point for Catmull-Clark,
// edge point to edge point for Loop), then the two halves of each parent edge. Faces: each
// parent face's children in its corner order (Loop: the three corner triangles, then the middle
// one). Child faces keep their parent's hole tag; child edges and vertices carry the decayed
// sharpness.
#pragma once

#include <string>
#include <vector>

#include "render/core/vec.h"
#include "render/mesh/control_mesh.h"
#include "render/rules/topology.h"

namespace limn::render::rules {

enum class Method { Masks, Factored };

struct Level {
  Topology topology;
  std::vector<Vec3> points;
};

// The base level of a validated mesh; throws InputError(InvalidMesh) when it is not manifold
// and std::invalid_argument for the bilinear scheme.
Level baseLevel(const mesh::ControlMesh& mesh);

// Why `method` cannot refine this mesh ("" when it can): the bilinear scheme (neither method),
// Loop, semi-sharp creases or corners, or smooth triangles next to a triangle (factored).
std::string unsupportedReason(const mesh::ControlMesh& mesh, Method method);

// One uniform step. Throws std::invalid_argument where unsupportedReason() is not empty.
Level refine(const Level& parent, Method method);

// `levels` uniform steps from the cage (levels >= 0).
Level refineUniform(const mesh::ControlMesh& mesh, int levels, Method method);

// A level as a ControlMesh: points, faces, creases (every edge with sharpness > 0, decayed),
// corners (vertices with sharpness > 0), holes, and the cage's scheme options. Boundary edges
// are not listed as creases: every reader of a ControlMesh makes them infinitely sharp.
mesh::ControlMesh toControlMesh(const Level& level);

// Catmull-Clark and Loop one step at a time: a ControlMesh in, the refined ControlMesh out.
mesh::ControlMesh subdivide(const mesh::ControlMesh& mesh, Method method);

}  // namespace limn::render::rules
