#include "render/raster/warm_up.h"

#include <exception>
#include <vector>

namespace limn::render::raster {

namespace {

tessellate::TriangleMesh tetrahedron() {
  tessellate::TriangleMesh mesh;
  mesh.positions = {{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}};
  for (const Vec3f& p : mesh.positions) mesh.normals.emplace_back(normalize(p.toDouble()));
  mesh.indices = {0, 1, 2, 0, 3, 1, 0, 2, 3, 1, 3, 2};
  return mesh;
}

LineOverlay edgesOf(const tessellate::TriangleMesh& mesh, bool occluded) {
  LineOverlay overlay{.pass = occluded ? "warm-up-occluded" : "warm-up",
                      .points = {},
                      .colors = {},
                      .occluded = occluded};
  for (size_t i = 0; i < mesh.indices.size(); i += 3) {
    overlay.points.push_back(mesh.positions[mesh.indices[i]]);
    overlay.points.push_back(mesh.positions[mesh.indices[i + 1]]);
    overlay.colors.push_back({255, 255, 255, 255});
  }
  return overlay;
}

}  // namespace

bool warmUp(Rasterizer& rasterizer) noexcept try {
  const tessellate::TriangleMesh mesh = tetrahedron();
  const Camera camera({0, 0, 6}, {0, 0, 0}, {0, 1, 0}, 40.0, Projection::Perspective, 0.0, 16, 16,
                      0.1, 100.0);
  const std::vector<LineOverlay> overlays = {edgesOf(mesh, true), edgesOf(mesh, false)};
  PassSelection every{.color = true,
                      .mask = true,
                      .depth = true,
                      .normal = true,
                      .wireframe = true,
                      .supersample = 2,
                      .antialias = 4};
  rasterizer.render(mesh, camera, every, Shading::Smooth, overlays);
  every.antialias = 1;  // the single-sample colour path
  rasterizer.render(mesh, camera, every, Shading::Flat, overlays);
  return true;
} catch (const std::exception&) {
  return false;
}

}  // namespace limn::render::raster
