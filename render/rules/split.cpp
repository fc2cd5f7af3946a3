// Child topologies of the two splits, numbered as OpenSubdiv's Far numbers a uniform level
// (refine.h): vertices of vertices, of faces (Catmull-Clark), of edges; edges inside faces,
// then edge halves; faces in parent order.
#include "render/core/parallel.h"
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
  for (int v = 0; v < p.vertexCount; ++v)
    c.vertexSharpness[v] = decaySharpness(p.vertexSharpness[v]);
}

// The child of parent face f at its corner k.
using ChildFace = int (*)(const Topology& p, int f, int k);
int quadChild(const Topology& p, int f, int k) { return p.faceOffsets[f] + k; }
int triangleChild(const Topology&, int f, int k) { return 4 * f + k; }

// Far's order of the faces around the child level's edges and vertices, which decides where
// a vertex's ring starts (limit tangents at creases and corners follow it): each half of a
// parent edge lists its faces in the parent edge's order; a child vertex of a vertex starts at
// the child of its parent's first face, a face point at the face's first child, and an edge
// point at the child, in the edge's first face, at the corner the face's winding runs the edge
// to. (Edges inside faces are ordered by the caller.)
void orderLikeFar(const Topology& p, int firstHalf, ChildFace child, int firstEdgeChild,
                  int firstFaceChild, Topology& c) {
  for (int e = 0; e < p.edgeCount(); ++e) {
    std::span<const int> parentFaces = p.edgeFacesOf(e);
    for (int end = 0; end < 2; ++end) {
      const int v = p.edgeVertices[e][end], half = firstHalf + 2 * e + end;
      for (size_t i = 0; i < parentFaces.size(); ++i) {
        c.edgeFaces[c.edgeFaceOffsets[half] + i] =
            child(p, parentFaces[i], p.cornerOf(parentFaces[i], v));
      }
    }
  }
  c.ringStart.assign(c.vertexCount, -1);
  for (int v = 0; v < p.vertexCount; ++v) {
    std::span<const int> faces = p.vertexFacesOf(v);
    if (faces.empty()) continue;
    const int first = p.ringStart.empty() || p.ringStart[v] < 0 ? faces[0] : p.ringStart[v];
    c.ringStart[v] = child(p, first, p.cornerOf(first, v));
  }
  if (firstFaceChild >= 0) {
    for (int f = 0; f < p.faceCount(); ++f) c.ringStart[firstFaceChild + f] = child(p, f, 0);
  }
  for (int e = 0; e < p.edgeCount(); ++e) {
    std::span<const int> faces = p.edgeFacesOf(e);
    if (faces.empty()) continue;
    const int f = faces[0], n = p.faceSize(f);
    const int k = p.cornerOf(f, p.edgeVertices[e][0]);
    const int end = p.faceVerts(f)[(k + 1) % n] == p.edgeVertices[e][1] ? p.edgeVertices[e][1]
                                                                        : p.edgeVertices[e][0];
    c.ringStart[firstEdgeChild + e] = child(p, f, p.cornerOf(f, end));
  }
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
  parallelFor(F, kParallelGrain, [&](size_t begin, size_t end) {
    for (int f = static_cast<int>(begin); f < static_cast<int>(end); ++f) {
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
  });
  c.completeAdjacency();
  for (int f = 0; f < F; ++f) {  // an inner edge lies between the children at its two sides
    const int n = p.faceSize(f), base = p.faceOffsets[f];
    for (int k = 0; k < n; ++k) {
      c.edgeFaces[c.edgeFaceOffsets[base + k]] = base + k;
      c.edgeFaces[c.edgeFaceOffsets[base + k] + 1] = base + (k + 1) % n;
    }
  }
  orderLikeFar(p, firstHalf, quadChild, edgeChild0, faceChild0, c);
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
  for (int f = 0; f < F; ++f) {  // an inner edge lies between a corner child and the middle one
    for (int k = 0; k < 3; ++k) {
      c.edgeFaces[c.edgeFaceOffsets[3 * f + k]] = 4 * f + k;
      c.edgeFaces[c.edgeFaceOffsets[3 * f + k] + 1] = 4 * f + 3;
    }
  }
  orderLikeFar(p, firstHalf, triangleChild, edgeChild0, -1, c);
  inheritTags(p, firstHalf, c);
  return c;
}

}  // namespace limn::render::rules
