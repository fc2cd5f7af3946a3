#include "render/oracle/triangle_scene.h"

#include <cstring>

namespace limn::render::oracle {

EmbreeScene buildTriangleScene(const tessellate::TriangleMesh& mesh, RTCBuildQuality quality,
                               const std::vector<uint32_t>* only) {
  FlushDenormalsScope ftz;
  RTCDevice device = embreeDevice();
  takeEmbreeError();  // report only this scene's errors
  EmbreeScene scene(rtcNewScene(device));
  // ROBUST: watertight edge tests, so rays through a shared edge or vertex always hit.
  rtcSetSceneFlags(scene.get(), RTC_SCENE_FLAG_ROBUST);
  rtcSetSceneBuildQuality(scene.get(), quality);

  const size_t triangles = only ? only->size() : mesh.triangleCount();
  if (triangles == 0) {  // nothing in view or no limit surface: every ray misses
    rtcCommitScene(scene.get());
    return scene;
  }
  RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  rtcSetGeometryBuildQuality(geometry, quality);
  // Buffers Embree allocates itself carry the padding its SIMD loads need past the last vertex.
  auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0,
                                                               RTC_FORMAT_FLOAT3, 3 * sizeof(float),
                                                               mesh.positions.size()));
  auto* indices = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
      geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), triangles));
  if (!vertices || !indices) {
    rtcReleaseGeometry(geometry);
    checkEmbree("triangle buffers");
  }
  static_assert(sizeof(Vec3f) == 3 * sizeof(float));
  std::memcpy(vertices, mesh.positions.data(), mesh.positions.size() * sizeof(Vec3f));
  if (only) {
    for (size_t k = 0; k < only->size(); ++k) {
      std::memcpy(indices + 3 * k, &mesh.indices[3 * size_t{(*only)[k]}], 3 * sizeof(uint32_t));
    }
  } else {
    std::memcpy(indices, mesh.indices.data(), mesh.indices.size() * sizeof(uint32_t));
  }
  rtcCommitGeometry(geometry);
  rtcAttachGeometry(scene.get(), geometry);
  rtcReleaseGeometry(geometry);
  rtcCommitScene(scene.get());
  checkEmbree("triangle scene");
  return scene;
}

}  // namespace limn::render::oracle
