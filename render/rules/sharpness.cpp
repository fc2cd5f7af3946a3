#include "render/rules/sharpness.h"

#include <algorithm>

#include "render/core/parallel.h"
#include "render/rules/steps.h"

namespace limn::render::rules {

float childEdgeSharpness(const Topology& t, int e, int v) {
  const float s = t.edgeSharpness[e];
  std::span<const int> around = t.vertexEdgesOf(v);
  if (t.options.creaseMethod == mesh::CreaseMethod::Uniform || around.size() < 2) {
    return decaySharpness(s);
  }
  if (!isSharp(s)) return 0.0f;
  if (isInfinite(s)) return kInfinitelySharp;
  float sum = 0.0f;
  int count = 0;
  for (int other : around) {
    if (isSemiSharp(t.edgeSharpness[other])) {
      sum += t.edgeSharpness[other];
      ++count;
    }
  }
  float child = s;
  if (count > 1) {
    float othersMean = (sum - s) / static_cast<float>(count - 1);
    child = 0.75f * s + 0.25f * othersMean;
  }
  child -= 1.0f;
  return isSharp(child) ? child : 0.0f;
}

bool edgePointIsMidpoint(const Topology& t, int e) {
  if (!isSharp(t.edgeSharpness[e])) return false;
  const auto [a, b] = t.edgeVertices[e];
  const int sharpHalves =
      isSharp(childEdgeSharpness(t, e, a)) + isSharp(childEdgeSharpness(t, e, b));
  return sharpHalves == 2 || t.edgeFacesOf(e).size() != 2;
}

Rule currentRule(const Topology& t, int v) {
  int sharp = 0;
  for (int e : t.vertexEdgesOf(v)) sharp += isSharp(t.edgeSharpness[e]);
  return ruleOf(t.vertexSharpness[v], sharp);
}

VertexRules vertexRules(const Topology& t) {
  VertexRules rules;
  rules.parent.resize(t.vertexCount);
  rules.child.resize(t.vertexCount);
  rules.transition.assign(t.vertexCount, 0.0f);
  const bool uniform = t.options.creaseMethod == mesh::CreaseMethod::Uniform;
  parallelFor(t.vertexCount, kParallelGrain, [&](size_t begin, size_t end) {
    for (size_t v = begin; v < end; ++v) {
      const float vs = t.vertexSharpness[v], childVs = decaySharpness(vs);
      int sharp = 0, childSharp = 0, transitions = 0;
      float transitionSum = 0.0f;
      if (isSharp(vs) && !isSharp(childVs)) {
        transitions = 1;
        transitionSum = vs;
      }
      for (int e : t.vertexEdgesOf(v)) {
        const float s = t.edgeSharpness[e], childS = childEdgeSharpness(t, e, v);
        sharp += isSharp(s);
        childSharp += isSharp(childS);
        // Uniform decay takes exactly the edges in (0, 1] to zero; Chaikin is asked directly.
        if (isSharp(s) && (uniform ? s <= 1.0f : !isSharp(childS))) {
          transitionSum += s;
          ++transitions;
        }
      }
      rules.parent[v] = ruleOf(vs, sharp);
      rules.child[v] = ruleOf(childVs, childSharp);
      if (transitions > 0) rules.transition[v] = std::min(1.0f, transitionSum / transitions);
    }
  });
  return rules;
}

}  // namespace limn::render::rules
