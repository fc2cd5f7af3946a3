// The marching-cubes case table, generated rather than typed in: for each of the 256 sign
// configurations of a cube's corners, the triangles (as cube edges) of the surface inside it.
//
// Ambiguous faces (two inside corners diagonally opposite) are resolved by one rule that looks
// at the face alone: inside corners are always separated. Both cubes sharing a face see the same
// corners and so draw the same segments across it, which is what makes the whole mesh free of
// holes; the face rule alone decides, with no complement symmetry (the original 15-case table's
// source of holes). The surface segments on the six faces are chained into loops and each loop
// is fanned into triangles, so a loop of k crossings gives k - 2 triangles, as the classic table
// does in the unambiguous cases.
//
// Corner c of a cube sits at offset (c & 1, (c >> 1) & 1, (c >> 2) & 1). Triangles wind
// counter-clockwise seen from outside (from where the field is below iso).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

namespace limn::render::implicit {

struct CubeEdge {
  int a, b;  // corners, a < b
  int axis;  // 0 x, 1 y, 2 z
};

// The 12 edges: x edges 0-3, y edges 4-7, z edges 8-11.
const std::array<CubeEdge, 12>& cubeEdges();

// triangles(c): three edge indices per triangle for configuration c (bit i set: corner i inside).
class CubeTable {
 public:
  static const CubeTable& instance();
  const std::vector<uint8_t>& triangles(int configuration) const { return cases_[configuration]; }

 private:
  CubeTable();
  std::array<std::vector<uint8_t>, 256> cases_;
};

}  // namespace limn::render::implicit
