// HalfedgeLevel: uniform refinement at the speed of its memory traffic, for the levels where
// the rules are simplest and the meshes largest: every face of one size (quads for
// Catmull-Clark, triangles for Loop), every sharpness 0 or infinite (so no rule changes from
// one level to the next). A Catmull-Clark mesh is all quads after one level, a Loop mesh is all
// triangles from the start, and semi-sharp features have decayed after ceil(max sharpness)
// levels, so a uniform refinement spends all but its first few levels here
// (refineUniformFast).
//
// The representation is a halfedge mesh of N-gons (as in Dupuy & Vanhoey, "A Halfedge
// Refinement Rule for Parallel Catmull-Clark Subdivision", HPG 2021, for quads; the same idea
// for Loop's triangles): halfedge h = N f + k is corner k of face f, running from vert[h] to the
// next corner; next and prev are implicit, and every array of the child level is a closed-form
// function of the parent's, computed per element in parallel. The child is numbered exactly as
// splitToQuads() and splitTriangles() number it (refine.h: Far's order), so a HalfedgeLevel and
// the Topology path give the same vertices in the same order.
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

// N = 4: Catmull-Clark's quads; N = 3: Loop's triangles.
template <int N>
struct HalfedgeLevel {
  static_assert(N == 3 || N == 4);
  static constexpr int kCorners = N;
  template <typename T>
  using Array = UninitializedVector<T>;  // every element is written by the step that makes it
  int vertexCount = 0;
  // ---- Per halfedge h = N f + k ----
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
  // Regular: the valence of a regular vertex of the scheme (4 quads, 6 triangles), none of its
  // faces a hole, no sharp edge, not a corner -- nearly every vertex of a refined mesh, whose
  // rules are then the B-spline's or the box spline's (kept so that no pass has to look at its
  // edges to know).
  Array<uint8_t> vertexRegular;
  // The outgoing halfedge the vertex's ring starts at, as orderedRing() starts it (a boundary
  // vertex at its boundary edge); -1 for a vertex with no face.
  Array<int> vertexStart;
  Array<Vec3> points;

  int faceCount() const { return static_cast<int>(vert.size() / N); }
  int edgeCount() const { return static_cast<int>(edgeVertices.size()); }
};

using QuadLevel = HalfedgeLevel<4>;
using TriangleLevel = HalfedgeLevel<3>;

// Halfedges are never negative: unsigned arithmetic keeps these to shifts and masks (quads) or
// one multiplication (triangles).
template <int N>
int faceOfHalfedge(int h) {
  return static_cast<int>(static_cast<unsigned>(h) / N);
}
template <int N>
int cornerOfHalfedge(int h) {
  return static_cast<int>(static_cast<unsigned>(h) % N);
}
template <int N>
int nextHalfedge(int h) {
  if constexpr (N == 4) return (h & ~3) | ((h + 1) & 3);
  return cornerOfHalfedge<N>(h) == N - 1 ? h - (N - 1) : h + 1;
}
template <int N>
int prevHalfedge(int h) {
  if constexpr (N == 4) return (h & ~3) | ((h + 3) & 3);
  return cornerOfHalfedge<N>(h) == 0 ? h + (N - 1) : h - 1;
}

// Visits the ring of vertex v (which has a face) in orderedRing() order: visit(h) for each
// outgoing halfedge h (face faceOfHalfedge(h), leading edge edge[h]). Returns the halfedge ending
// at v that closes a boundary ring (its edge is the ring's last), or -1 for an interior ring.
template <int N, typename Visit>
int forEachAround(const HalfedgeLevel<N>& q, int v, Visit visit) {
  const int start = q.vertexStart[v];
  int h = start;
  do {
    visit(h);
    const int trailing = prevHalfedge<N>(h);
    if (q.twin[trailing] < 0) return trailing;
    h = q.twin[trailing];
  } while (h != start);
  return -1;
}

// The corners per face a level can continue with as a HalfedgeLevel: 4 for Catmull-Clark with
// quads only, 3 for Loop (triangles only), with every edge and vertex sharpness 0 or infinite;
// 0 when it cannot.
int halfedgeCorners(const Topology& topology);

// The same level as a HalfedgeLevel (halfedgeCorners(level.topology) == N must hold).
template <int N>
HalfedgeLevel<N> toHalfedgeLevel(const Level& level);

// One Catmull-Clark step; one Loop step.
QuadLevel refineQuads(const QuadLevel& parent);
TriangleLevel refineTriangles(const TriangleLevel& parent);

// Limit position and unit limit normal (zero where undefined) of every vertex, by the masks of
// limit.h (the same values as limitOf() on the equivalent Level, up to rounding).
struct HalfedgeLimit {
  std::vector<Vec3> positions, normals;
};
template <int N>
HalfedgeLimit limitOfHalfedges(const HalfedgeLevel<N>& level);

// What a renderer draws at each vertex, in one pass over the rings, written straight into float
// arrays of level.vertexCount entries: the position (the refined point, or its limit with
// pushToLimit), the limit position, and the unit limit normal turned to the side its faces face
// (their own normal where the limit tangents are degenerate); holes do not count as faces.
template <int N>
void drawnVertices(const HalfedgeLevel<N>& level, bool pushToLimit, Vec3f* positions,
                   Vec3f* limitPositions, Vec3f* normals);

// `levels` uniform steps of limn's masks from the cage: on the Topology while halfedgeCorners()
// is 0, as a HalfedgeLevel after. `quads` (Catmull-Clark) or `triangles` (Loop) holds the
// result when at least one step ran on halfedges; otherwise `level` does.
struct FastRefinement {
  std::optional<QuadLevel> quads;
  std::optional<TriangleLevel> triangles;
  Level level;
  int topologySteps = 0;  // steps that ran on the Topology
};
FastRefinement refineUniformFast(const mesh::ControlMesh& mesh, int levels);

}  // namespace limn::render::rules
