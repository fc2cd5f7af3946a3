#include "render/patches/patch_image.h"

#include <algorithm>
#include <array>

namespace limn::render::patches {

namespace {

constexpr std::array<Vec3f, 9> kLevelColors = {
    Vec3f{0.20f, 0.40f, 0.90f}, Vec3f{0.15f, 0.75f, 0.85f}, Vec3f{0.25f, 0.70f, 0.30f},
    Vec3f{0.65f, 0.80f, 0.20f}, Vec3f{0.95f, 0.80f, 0.15f}, Vec3f{0.95f, 0.50f, 0.15f},
    Vec3f{0.90f, 0.20f, 0.20f}, Vec3f{0.85f, 0.25f, 0.70f}, Vec3f{0.55f, 0.30f, 0.85f}};
constexpr Vec3f kIrregularColor{0.55f, 0.55f, 0.55f};

Vec3f mix(const Vec3f& a, const Vec3f& b, float t) {
  return {a.x + (b.x - a.x) * t, a.y + (b.y - a.y) * t, a.z + (b.z - a.z) * t};
}

}  // namespace

Vec3f patchColor(const Patch& patch) {
  const Vec3f level = kLevelColors[std::min<size_t>(patch.depth, kLevelColors.size() - 1)];
  switch (patch.kind) {
    case PatchKind::Regular:
      return level;
    case PatchKind::Boundary:
      return mix(level, Vec3f{1, 1, 1}, 0.5f);
    case PatchKind::Crease:
      return mix(level, Vec3f{0, 0, 0}, 0.45f);
    case PatchKind::Irregular:
      return kIrregularColor;
  }
  return level;
}

tessellate::TriangleMesh patchColoredMesh(const PatchMesh& tessellation, const PatchSet& set) {
  const tessellate::TriangleMesh& in = tessellation.mesh;
  tessellate::TriangleMesh out;
  const size_t corners = in.indices.size();
  out.positions.reserve(corners);
  out.normals.reserve(corners);
  out.albedo.reserve(corners);
  out.indices.reserve(corners);
  for (size_t c = 0; c < corners; ++c) {
    const uint32_t v = in.indices[c];
    out.positions.push_back(in.positions[v]);
    out.normals.push_back(in.normals[v]);
    out.albedo.push_back(patchColor(set.patches()[tessellation.trianglePatch[c / 3]]));
    out.indices.push_back(static_cast<uint32_t>(c));
  }
  return out;
}

}  // namespace limn::render::patches
