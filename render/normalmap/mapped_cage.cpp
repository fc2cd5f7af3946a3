#include "render/normalmap/mapped_cage.h"

#include <vector>

namespace limn::render::normalmap {

namespace {

using OpenSubdiv::Bfr::Parameterization;

// Appends one vertex of face `face` at parameter uv, with texture coordinate `texcoord`.
uint32_t addVertex(const subdiv::LimitSurface& surface, int face, Vec2 uv, const Vec3& position,
                   Vec2f texcoord, tessellate::TriangleMesh& out) {
  const subdiv::LimitSample limit = surface.evaluate(face, uv.x, uv.y);
  out.positions.emplace_back(position);
  out.normals.emplace_back(limit.normal);
  out.limitPositions.emplace_back(limit.position);
  out.texcoords.push_back(texcoord);
  return static_cast<uint32_t>(out.positions.size() - 1);
}

void addLine(uint32_t a, uint32_t b, tessellate::TriangleMesh& out) {
  out.lines.push_back(a);
  out.lines.push_back(b);
}

}  // namespace

tessellate::TriangleMesh mappedCage(const subdiv::LimitSurface& surface, const NormalAtlas& atlas) {
  const mesh::ControlMesh& cage = surface.mesh();
  tessellate::TriangleMesh out;
  out.normalMap = atlas.image();
  std::vector<Vec3> corners;
  size_t offset = 0;
  for (int f = 0; f < cage.faceCount(); ++f) {
    const int n = cage.faceVertexCounts[f];
    corners.clear();
    for (int k = 0; k < n; ++k) corners.push_back(cage.points[cage.faceVertexIndices[offset + k]]);
    offset += n;
    if (!atlas.hasChart(f)) continue;
    const Parameterization p = surface.parameterization(f);

    if (!p.HasSubFaces()) {
      std::vector<uint32_t> ids;
      for (int k = 0; k < n; ++k) {
        const Vec2 uv = surface.cornerUV(f, k);
        ids.push_back(addVertex(surface, f, uv, corners[k], atlas.coordinate(f, uv), out));
      }
      for (int k = 1; k + 1 < n; ++k) {
        out.indices.insert(out.indices.end(), {ids[0], ids[k], ids[k + 1]});
      }
      for (int k = 0; k < n; ++k) addLine(ids[k], ids[(k + 1) % n], out);
      continue;
    }

    Vec3 centroid;
    for (const Vec3& c : corners) centroid += c / n;
    for (int k = 0; k < n; ++k) {
      // Sub-face k at normalised (s, t): (0,0) corner k, (1,0) the midpoint of edge k (towards
      // corner k + 1), (1,1) the centre, (0,1) the midpoint of edge k - 1.
      const Vec3 next = (corners[k] + corners[(k + 1) % n]) * 0.5;
      const Vec3 previous = (corners[k] + corners[(k + n - 1) % n]) * 0.5;
      const Vec3 positions[4] = {corners[k], next, centroid, previous};
      const Vec2 st[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
      uint32_t ids[4];
      for (int i = 0; i < 4; ++i) {
        const double in[2] = {st[i].x, st[i].y};
        double uv[2];
        p.ConvertNormalizedSubFaceToCoord(k, in, uv);
        ids[i] = addVertex(surface, f, {uv[0], uv[1]}, positions[i],
                           atlas.subFaceCoordinate(f, k, st[i]), out);
      }
      out.indices.insert(out.indices.end(), {ids[0], ids[1], ids[2], ids[0], ids[2], ids[3]});
      addLine(ids[0], ids[1], out);  // the first half of edge k
      addLine(ids[3], ids[0], out);  // the second half of edge k - 1
    }
  }
  return out;
}

}  // namespace limn::render::normalmap
