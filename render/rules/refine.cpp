#include "render/rules/refine.h"

#include <stdexcept>

#include "render/rules/sharpness.h"
#include "render/rules/steps.h"

namespace limn::render::rules {

namespace {

std::string reasonFor(mesh::Scheme scheme, Method method, bool semiSharp, bool smoothTriangles) {
  if (scheme == mesh::Scheme::Bilinear) {
    return "limn's own rules cover the catmull-clark and loop schemes, not bilinear";
  }
  if (method == Method::Masks) return "";
  if (scheme == mesh::Scheme::Loop) {
    return "the factored method is Catmull-Clark's; loop meshes are refined by the masks";
  }
  if (semiSharp) {
    return "the factored method has no form for semi-sharp creases or corners (sharpness "
           "between 0 and 10); use the masks or OpenSubdiv";
  }
  if (smoothTriangles) {
    return "the factored method has no form for the smooth-triangle rule; use the masks or "
           "OpenSubdiv";
  }
  return "";
}

bool hasTriangle(const std::vector<int>& faceSizes) {
  for (int n : faceSizes) {
    if (n == 3) return true;
  }
  return false;
}

std::vector<int> faceSizes(const Topology& t) {
  std::vector<int> sizes(t.faceCount());
  for (int f = 0; f < t.faceCount(); ++f) sizes[f] = t.faceSize(f);
  return sizes;
}

}  // namespace

std::string unsupportedReason(const mesh::ControlMesh& m, Method method) {
  bool semiSharp = false;
  for (const mesh::Crease& c : m.creases) semiSharp = semiSharp || isSemiSharp(c.sharpness);
  for (const mesh::Corner& c : m.corners) semiSharp = semiSharp || isSemiSharp(c.sharpness);
  bool smoothTriangles =
      m.triangleSubdivision == mesh::TriangleSubdivision::Smooth && hasTriangle(m.faceVertexCounts);
  return reasonFor(m.scheme, method, semiSharp, smoothTriangles);
}

Level baseLevel(const mesh::ControlMesh& m) {
  if (m.scheme == mesh::Scheme::Bilinear) {
    throw std::invalid_argument(reasonFor(m.scheme, Method::Masks, false, false));
  }
  return {Topology::fromMesh(m), m.points};
}

Level refine(const Level& parent, Method method) {
  const Topology& t = parent.topology;
  bool semiSharp = false;
  for (float s : t.edgeSharpness) semiSharp = semiSharp || isSemiSharp(s);
  for (float s : t.vertexSharpness) semiSharp = semiSharp || isSemiSharp(s);
  bool smoothTriangles = t.options.triangleSubdivision == mesh::TriangleSubdivision::Smooth &&
                         hasTriangle(faceSizes(t));
  std::string reason = reasonFor(t.options.scheme, method, semiSharp, smoothTriangles);
  if (!reason.empty()) throw std::invalid_argument(reason);

  Level child;
  if (t.options.scheme == mesh::Scheme::Loop) {
    child.topology = splitTriangles(t);
    child.points = loopPoints(t, parent.points);
  } else {
    child.topology = splitToQuads(t);
    child.points = method == Method::Masks ? catmullClarkPoints(t, parent.points)
                                           : factoredPoints(t, child.topology, parent.points);
  }
  return child;
}

Level refineUniform(const mesh::ControlMesh& m, int levels, Method method) {
  Level level = baseLevel(m);
  for (int l = 0; l < levels; ++l) level = refine(level, method);
  return level;
}

mesh::ControlMesh toControlMesh(const Level& level) {
  const Topology& t = level.topology;
  mesh::ControlMesh m;
  m.scheme = t.options.scheme;
  m.boundary = t.options.boundary;
  m.creaseMethod = t.options.creaseMethod;
  m.triangleSubdivision = t.options.triangleSubdivision;
  m.points = level.points;
  m.faceVertexIndices = t.faceVertices;
  m.faceVertexCounts = faceSizes(t);
  for (int e = 0; e < t.edgeCount(); ++e) {
    if (isSharp(t.edgeSharpness[e]) && !t.isBoundaryEdge(e)) {
      m.creases.push_back({t.edgeVertices[e][0], t.edgeVertices[e][1], t.edgeSharpness[e]});
    }
  }
  for (int v = 0; v < t.vertexCount; ++v) {
    if (isSharp(t.vertexSharpness[v])) m.corners.push_back({v, t.vertexSharpness[v]});
  }
  for (int f = 0; f < t.faceCount(); ++f) {
    if (t.faceHole[f]) m.holes.push_back(f);
  }
  return m;
}

mesh::ControlMesh subdivide(const mesh::ControlMesh& m, Method method) {
  return toControlMesh(refine(baseLevel(m), method));
}

}  // namespace limn::render::rules
