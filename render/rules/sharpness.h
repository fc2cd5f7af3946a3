// Sharpness and vertex rules: which mask a vertex takes (smooth, dart, crease, corner), how
// sharpness decays from one level to the next, and the weight that blends the parent's and
// the child's masks when a semi-sharp feature turns smooth. These follow OpenSubdiv's Sdc
// definitions, in single precision as OpenSubdiv computes them, so that the fractional weights
// agree bit for bit:
//   - a vertex with sharpness > 0 is a corner; otherwise its sharp edges (sharpness > 0)
//     decide: none smooth, one dart, two crease, more corner;
//   - uniform decay: infinitely sharp stays, s > 1 becomes s - 1, anything else 0;
//   - Chaikin decay of an edge at one end: 3/4 of its own sharpness plus 1/4 of the mean of the
//     other semi-sharp edges at that vertex, minus 1 (uniform when it is the only one);
//   - the transition weight at a vertex is the mean sharpness of the features that turn smooth
//     in this step, at most 1.
#pragma once

#include <span>

#include "render/rules/topology.h"

namespace limn::render::rules {

enum class Rule { Smooth, Dart, Crease, Corner };

inline bool isSharp(float s) { return s > 0.0f; }
inline bool isInfinite(float s) { return s >= kInfinitelySharp; }
inline bool isSemiSharp(float s) { return s > 0.0f && s < kInfinitelySharp; }

inline float decaySharpness(float s) {
  if (!isSharp(s)) return 0.0f;
  if (isInfinite(s)) return kInfinitelySharp;
  return s > 1.0f ? s - 1.0f : 0.0f;
}

inline Rule ruleOf(float vertexSharpness, int sharpEdges) {
  if (isSharp(vertexSharpness)) return Rule::Corner;
  switch (sharpEdges) {
    case 0:
      return Rule::Smooth;
    case 1:
      return Rule::Dart;
    case 2:
      return Rule::Crease;
    default:
      return Rule::Corner;
  }
}

// The sharpness of the child of edge `e` that ends at its vertex `v` (an end of e).
float childEdgeSharpness(const Topology& t, int e, int v);

// Whether the point of edge e is its midpoint (the sharp rule): a sharp edge whose two halves
// stay sharp one level down, or a sharp edge without two faces.
bool edgePointIsMidpoint(const Topology& t, int e);

// The smooth edge-point weights of a semi-sharp edge turning smooth in this step (sharpness s,
// or a Chaikin dart), blended towards the midpoint by s: vw per end, fw per face term.
inline void blendTowardsMidpoint(float s, double& vw, double& fw) {
  if (!isSharp(s)) return;
  const double w = s;
  vw = w * 0.5 + (1.0 - w) * vw;
  fw *= 1.0 - w;
}

// Per vertex of `t`: the rule of the vertex itself, and of its child one level down.
struct VertexRules {
  std::vector<Rule> parent, child;
  // Weight of the parent's mask where parent and child rules differ (0 elsewhere).
  std::vector<float> transition;
};
VertexRules vertexRules(const Topology& t);

// The rule of a vertex at its own level (what the limit masks use).
Rule currentRule(const Topology& t, int v);

}  // namespace limn::render::rules
