#include "render/oracle/reference_scene.h"

#include <chrono>
#include <cstdio>

#include "render/mesh/content_hash.h"
#include "render/oracle/triangle_scene.h"

namespace limn::render::oracle {

namespace {

double msSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

// Embree's BVH of a triangle geometry, per triangle: measured as the growth of the resident
// size over a 1M-triangle build at LOW quality (tests/unit/oracle_test ReferenceSceneBytes).
constexpr size_t kBvhBytesPerTriangle = 100;

size_t estimateBytes(const tessellate::TriangleMesh& mesh) {
  return mesh.positions.size() * sizeof(mesh.positions[0]) +
         mesh.normals.size() * sizeof(mesh.normals[0]) +
         mesh.indices.size() * sizeof(mesh.indices[0]) +
         mesh.cornerUVs.size() * sizeof(mesh.cornerUVs[0]) +
         mesh.triangleFaces.size() * sizeof(mesh.triangleFaces[0]) +
         mesh.triangleCount() * kBvhBytesPerTriangle;
}

}  // namespace

std::shared_ptr<const ReferenceScene> buildReferenceScene(const subdiv::LimitSurface& surface,
                                                          const Camera& camera,
                                                          const CancelToken& cancel) {
  auto scene = std::make_shared<ReferenceScene>();
  auto start = std::chrono::steady_clock::now();
  scene->tessellation = tessellateForReference(surface, camera, cancel);
  scene->tessellateMs = msSince(start);
  cancel.check();
  start = std::chrono::steady_clock::now();
  // LOW: the reference casts about one ray per pixel plus a few per outline pixel, too few for a
  // slower, better BVH to pay off (triangle_scene.h has the measurements).
  scene->scene = buildTriangleScene(scene->tessellation.mesh, RTC_BUILD_QUALITY_LOW);
  scene->bvhMs = msSince(start);
  scene->bytes = estimateBytes(scene->tessellation.mesh);
  return scene;
}

std::string referenceSceneKey(const mesh::ControlMesh& mesh, const Camera& c) {
  char view[512];
  std::snprintf(
      view, sizeof view,
      "|%.17g,%.17g,%.17g|%.17g,%.17g,%.17g|%.17g,%.17g,%.17g|%.17g|%d|%.17g|%dx%d|%.17g,%.17g",
      c.eye().x, c.eye().y, c.eye().z, c.target().x, c.target().y, c.target().z, c.up().x, c.up().y,
      c.up().z, c.fovYDeg(), static_cast<int>(c.projection()), c.orthoHeight(), c.width(),
      c.height(), c.nearPlane(), c.farPlane());
  return mesh::contentHash(mesh) + view;
}

std::shared_ptr<const ReferenceScene> ReferenceSceneCache::get(const subdiv::LimitSurface& surface,
                                                               const Camera& camera,
                                                               const CancelToken& cancel,
                                                               bool* hit) {
  const std::string key = referenceSceneKey(surface.mesh(), camera);
  {
    std::lock_guard lock(mutex_);
    auto it = index_.find(key);
    if (it != index_.end()) {
      lru_.splice(lru_.begin(), lru_, it->second);
      ++hits_;
      *hit = true;
      return it->second->second;
    }
    ++misses_;
  }
  *hit = false;
  std::shared_ptr<const ReferenceScene> scene = buildReferenceScene(surface, camera, cancel);
  std::lock_guard lock(mutex_);
  insertLocked(key, scene);
  return scene;
}

void ReferenceSceneCache::insertLocked(const std::string& key,
                                       std::shared_ptr<const ReferenceScene> scene) {
  if (scene->bytes > capacity_) return;  // would evict everything and still not fit
  if (auto it = index_.find(key); it != index_.end()) {
    bytes_ -= it->second->second->bytes;
    lru_.erase(it->second);
    index_.erase(it);
  }
  while (!lru_.empty() && bytes_ + scene->bytes > capacity_) {
    bytes_ -= lru_.back().second->bytes;
    index_.erase(lru_.back().first);
    lru_.pop_back();
    ++evictions_;
  }
  bytes_ += scene->bytes;
  lru_.emplace_front(key, std::move(scene));
  index_[key] = lru_.begin();
}

ReferenceSceneCache::Counters ReferenceSceneCache::counters() const {
  std::lock_guard lock(mutex_);
  return {hits_, misses_, evictions_, lru_.size(), bytes_, capacity_};
}

void ReferenceSceneCache::clear() {
  std::lock_guard lock(mutex_);
  lru_.clear();
  index_.clear();
  bytes_ = 0;
}

}  // namespace limn::render::oracle
