// Child topologies of the two splits, numbered as OpenSubdiv's Far numbers a uniform level
// (refine.h): vertices of vertices, of faces (Catmull-Clark), of edges; edges inside faces,
// then edge halves; faces in parent order.
#include "render/rules/sharpness.h"
#include "render/rules/steps.h"

namespace limn::render::rules {

namespace {

// The half of parent edge e that ends at its vertex v, numbered after `firstHalf`.
int halfAt(const Topology& p, int firstHalf, int e, int v) {
  return firstHalf + 2 * e + (p.edgeVertices[e][0] == v ? 0 : 1);
}

// Child edge and vertex tags: edge halves carry their end's decayed sharpness, edges inside
// faces are smooth, children of vertices keep their parent's decayed sharpness.
void inheritTags(const Topology& p, int firstHalf, Topology& c) {
  c.edgeSharpness.assign(c.edgeCount(), 0.0f);
  for (int e = 0; e < p.edgeCount(); ++e) {
    if (!isSharp(p.edgeSharpness[e])) continue;
    for (int end = 0; end < 2; ++end) {
      c.edgeSharpness[firstHalf + 2 * e + end] = childEdgeSharpness(p, e, p.edgeVertices[e][end]);
    }
  }
  c.vertexSharpness.assign(c.vertexCount, 0.0f);
  for (int v = 0; v < p.vertexCount; ++v) c.vertexSharpness[v] = decaySharpness(p.vertexSharpness[v]);
}

void addHalves(const Topology& p, int firstEdgeChild, int firstHalf, Topology& c) {
  for (int e = 0; e < p.edgeCount(); ++e) {
    c.edgeVertices[firstHalf + 2 * e] = {firstEdgeChild + e, p.edgeVertices[e][0]};
    c.edgeVertices[firstHalf + 2 * e + 1] = {firstEdgeChild + e, p.edgeVertices[e][1]};
  }
}

}  // namespace

Topology splitToQuads(const Topology& p) {
  const int V = p.vertexCount, F = p.faceCount(), E = p.edgeCount();
  const int corners = static_cast<int>(p.faceVertices.size());
  const int faceChild0 = V, edgeChild0 = V + F, firstHalf = corners;
  Topology c;
  c.options = p.options;
  c.vertexCount = V + F + E;

  c.edgeVertices.resize(corners + 2 * E);
  for (int f = 0; f < F; ++f) {
    std::span<const int> fe = p.faceEdgesOf(f);
    for (size_t k = 0; k < fe.size(); ++k) {
      c.edgeVertices[p.faceOffsets[f] + k] = {faceChild0 + f, edgeChild0 + fe[k]};
    }
  }
  addHalves(p, edgeChild0, firstHalf, c);

  c.faceOffsets.resize(corners + 1);
  for (int q = 0; q <= corners; ++q) c.faceOffsets[q] = 4 * q;
  c.faceVertices.resize(4 * corners);
  c.faceEdges.resize(4 * corners);
  c.faceHole.resize(corners);
  for (int f = 0; f < F; ++f) {
    std::span<const int> fv = p.faceVerts(f), fe = p.faceEdgesOf(f);
    const int n = static_cast<int>(fv.size()), base = p.faceOffsets[f];
    for (int i = 0; i < n; ++i) {
      const int prev = (i + n - 1) % n;
      const int verts[4] = {fv[i], edgeChild0 + fe[i], faceChild0 + f, edgeChild0 + fe[prev]};
      const int edges[4] = {halfAt(p, firstHalf, fe[i], fv[i]), base + i, base + prev,
                            halfAt(p, firstHalf, fe[prev], fv[i])};
      const int rotation = n == 4 ? i : 0;
      const int q = base + i;
      for (int j = 0; j < 4; ++j) {
        c.faceVertices[4 * q + (j + rotation) % 4] = verts[j];
        c.faceEdges[4 * q + (j + rotation) % 4] = edges[j];
      }
      c.faceHole[q] = p.faceHole[f];
    }
  }
  c.completeAdjacency();
  inheritTags(p, firstHalf, c);
  return c;
}

Topology splitTriangles(const Topology& p) {
  const int V = p.vertexCount, F = p.faceCount(), E = p.edgeCount();
  const int edgeChild0 = V, firstHalf = 3 * F;
  Topology c;
  c.options = p.options;
  c.vertexCount = V + E;

  c.edgeVertices.resize(3 * F + 2 * E);
  for (int f = 0; f < F; ++f) {
    std::span<const int> fe = p.faceEdgesOf(f);
    for (int k = 0; k < 3; ++k) {
      c.edgeVertices[3 * f + k] = {edgeChild0 + fe[k], edgeChild0 + fe[(k + 2) % 3]};
    }
  }
  addHalves(p, edgeChild0, firstHalf, c);

  c.faceOffsets.resize(4 * F + 1);
  for (int t = 0; t <= 4 * F; ++t) c.faceOffsets[t] = 3 * t;
  c.faceVertices.resize(12 * F);
  c.faceEdges.resize(12 * F);
  c.faceHole.resize(4 * F);
  for (int f = 0; f < F; ++f) {
    std::span<const int> fv = p.faceVerts(f), fe = p.faceEdgesOf(f);
    for (int i = 0; i < 3; ++i) {
      const int prev = (i + 2) % 3;
      const int verts[3] = {fv[i], edgeChild0 + fe[i], edgeChild0 + fe[prev]};
      const int edges[3] = {halfAt(p, firstHalf, fe[i], fv[i]), 3 * f + i,
                            halfAt(p, firstHalf, fe[prev], fv[i])};
      const int t = 4 * f + i;
      for (int j = 0; j < 3; ++j) {
        c.faceVertices[3 * t + (j + i) % 3] = verts[j];
        c.faceEdges[3 * t + (j + i) % 3] = edges[j];
      }
      c.faceHole[t] = p.faceHole[f];
    }
    // The middle triangle: edge points 1, 2, 0, joined by the inner edges 2, 0, 1.
    const int t = 4 * f + 3;
    const int verts[3] = {edgeChild0 + fe[1], edgeChild0 + fe[2], edgeChild0 + fe[0]};
    const int edges[3] = {3 * f + 2, 3 * f + 0, 3 * f + 1};
    for (int j = 0; j < 3; ++j) {
      c.faceVertices[3 * t + j] = verts[j];
      c.faceEdges[3 * t + j] = edges[j];
    }
    c.faceHole[t] = p.faceHole[f];
  }
  c.completeAdjacency();
  inheritTags(p, firstHalf, c);
  return c;
}

}  // namespace limn::render::rules
