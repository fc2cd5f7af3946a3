// The pieces of one refinement step, shared by refine.cpp and the scheme files: the child
// topology of each split (numbered as refine.h describes) and the points of each rule set.
// Internal to render/rules.
#pragma once

#include <vector>

#include "render/core/vec.h"
#include "render/rules/topology.h"

namespace limn::render::rules {

// Elements per task of the parallel loops over a level's faces, edges and vertices.
inline constexpr size_t kParallelGrain = 16384;

// Catmull-Clark's split: every n-gon into n quads (a quad's children keep its orientation:
// child i has the child of corner i at its corner i; other faces' children start there).
Topology splitToQuads(const Topology& parent);
// Loop's split: every triangle into four.
Topology splitTriangles(const Topology& parent);

std::vector<Vec3> catmullClarkPoints(const Topology& parent, const std::vector<Vec3>& points);
std::vector<Vec3> loopPoints(const Topology& parent, const std::vector<Vec3>& points);
// Needs the child topology made by splitToQuads(parent): the averaging runs over its quads.
std::vector<Vec3> factoredPoints(const Topology& parent, const Topology& child,
                                 const std::vector<Vec3>& points);

}  // namespace limn::render::rules
