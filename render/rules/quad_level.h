// QuadLevel: Catmull-Clark refinement at the speed of its memory traffic, for the levels where
// the rules are simplest and the meshes largest: every face a quad, every sharpness 0 or
// infinite (so no rule changes from one level to the next). After one level every face is a
// quad, and semi-sharp features have decayed after ceil(max sharpness) levels, so a uniform
// refinement spends all but its first few levels here (refineUniformFast).
//
// The representation is a halfedge mesh of quads (as in Dupuy & Vanhoey, "A Halfedge Refinement
// Rule for Parallel Catmull-Clark Subdivision", HPG 2021): halfedge h = 4 f + k is corner k of
// face f, running from vert[h] to the next corner; next and prev are implicit, and every array
// of the child level is a closed-form function of the parent's, computed per element in
// parallel. The child is numbered exactly as splitToQuads() numbers it (refine.h: Far's order),
// so a QuadLevel and the Topology path give the same vertices in the same order.
//
// Every loop writes each output element from one task, reading only the parent level: the
// result does not depend on the number of threads.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "render/core/uninitialized.h"
#include "render/core/vec.h"
#include "render/rules/refine.h"

namespace limn::render::rules {

struct QuadLevel {
  template <typename T>
  using Array = UninitializedVector<T>;  // every element is written by the step that makes it
  int vertexCount = 0;
  // ---- Per halfedge h = 4 f + k ----
  Array<int> vert;  // corner k of face f
  Array<int> edge;  // the edge from corner k to corner k + 1
  Array<int> twin;  // the halfedge of the same edge in the other face; -1 on a boundary
  // ---- Per face ----
  Array<uint8_t> faceHole;
  // ---- Per edge ----
  Array<std::array<int, 2>> edgeVertices;
  Array<int> edgeFirst;      // its halfedge in the edge's first face (Far's face order)
  Array<uint8_t> edgeSharp;  // infinitely sharp (boundary edges are)
  // ---- Per vertex ----
  Array<uint8_t> vertexCorner;  // infinitely sharp corner
  // Regular: four faces, none of them a hole, no sharp edge, not a corner -- nearly every vertex
  // of a refined quad mesh, whose rules are then the B-spline's (kept so that no pass has to
  // look at its edges to know).
  Array<uint8_t> vertexRegular;
  // The outgoing halfedge the vertex's ring starts at, as orderedRing() starts it (a boundary
  // vertex at its boundary edge); -1 for a vertex with no face.
  Array<int> vertexStart;
  Array<Vec3> points;

  int faceCount() const { return static_cast<int>(vert.size() / 4); }
  int edgeCount() const { return static_cast<int>(edgeVertices.size()); }
};

inline int nextHalfedge(int h) { return (h & ~3) | ((h + 1) & 3); }
inline int prevHalfedge(int h) { return (h & ~3) | ((h + 3) & 3); }
inline int faceOfHalfedge(int h) { return h >> 2; }

// Visits the ring of vertex v (which has a face) in orderedRing() order: visit(h) for each
// outgoing halfedge h (face faceOfHalfedge(h), leading edge edge[h]). Returns the halfedge ending
// at v that closes a boundary ring (its edge is the ring's last), or -1 for an interior ring.
template <typename Visit>
int forEachAround(const QuadLevel& q, int v, Visit visit) {
  const int start = q.vertexStart[v];
  int h = start;
  do {
    visit(h);
    const int trailing = prevHalfedge(h);
    if (q.twin[trailing] < 0) return trailing;
    h = q.twin[trailing];
  } while (h != start);
  return -1;
}

// Whether a level can continue as a QuadLevel: Catmull-Clark, quads only, every edge and vertex
// sharpness 0 or infinite.
bool quadReady(const Topology& topology);

// The same level as a QuadLevel (quadReady(level.topology) must hold).
QuadLevel toQuadLevel(const Level& level);

// One Catmull-Clark step.
QuadLevel refineQuads(const QuadLevel& parent);

// Limit position and unit limit normal (zero where undefined) of every vertex, by the masks of
// limit.h (the same values as limitOf() on the equivalent Level, up to rounding).
struct QuadLimit {
  std::vector<Vec3> positions, normals;
};
QuadLimit limitOfQuads(const QuadLevel& level);

// What a renderer draws at each vertex, in one pass over the rings, written straight into float
// arrays of level.vertexCount entries: the position (the refined point, or its limit with
// pushToLimit), the limit position, and the unit limit normal turned to the side its faces face
// (their own normal where the limit tangents are degenerate); holes do not count as faces.
void drawnVertices(const QuadLevel& level, bool pushToLimit, Vec3f* positions,
                   Vec3f* limitPositions, Vec3f* normals);

// `levels` uniform steps of limn's masks from the cage: on the Topology while the level is not
// quadReady(), as a QuadLevel after. `quads` holds the result when at least one step ran as a
// QuadLevel; otherwise `level` does.
struct FastRefinement {
  std::optional<QuadLevel> quads;
  Level level;
  int topologySteps = 0;  // steps that ran on the Topology
};
FastRefinement refineUniformFast(const mesh::ControlMesh& mesh, int levels);

}  // namespace limn::render::rules
