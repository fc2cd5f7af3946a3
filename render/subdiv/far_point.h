// FarPoint: a position in the shape OpenSubdiv's Far interpolates through (PrimvarRefiner,
// stencil and patch tables call Clear() and AddWithWeight() on their primvar type). Far hands
// weights as float or as double, depending on the table's precision; both accumulate in double.
#pragma once

#include "render/core/vec.h"

namespace limn::render::subdiv {

struct FarPoint {
  Vec3 p{0, 0, 0};

  void Clear(void* = nullptr) { p = {0, 0, 0}; }
  void AddWithWeight(const FarPoint& src, double weight) { p += src.p * weight; }
};

}  // namespace limn::render::subdiv
