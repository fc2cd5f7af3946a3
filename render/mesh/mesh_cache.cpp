#include "render/mesh/mesh_cache.h"

#include <utility>

#include "render/mesh/content_hash.h"

namespace limn::render::mesh {

size_t MeshCache::bytesOf(const ControlMesh& mesh) {
  return sizeof(ControlMesh) + mesh.points.size() * sizeof(Vec3) +
         (mesh.faceVertexCounts.size() + mesh.faceVertexIndices.size() + mesh.holes.size()) *
             sizeof(int) +
         mesh.creases.size() * sizeof(Crease) + mesh.corners.size() * sizeof(Corner);
}

MeshCache::Stored MeshCache::put(ControlMesh mesh) {
  std::string id = contentHash(mesh);
  const size_t bytes = bytesOf(mesh);
  std::lock_guard lock(mutex_);
  if (auto it = byId_.find(id); it != byId_.end()) {
    order_.splice(order_.begin(), order_, it->second);
    return {std::move(id), true};
  }
  if (bytes > capacityBytes_) return {std::move(id), false};
  while (bytes_ + bytes > capacityBytes_ && !order_.empty()) {
    bytes_ -= order_.back().bytes;
    byId_.erase(order_.back().id);
    order_.pop_back();
    ++evictions_;
  }
  order_.push_front({id, std::make_shared<const ControlMesh>(std::move(mesh)), bytes});
  byId_[id] = order_.begin();
  bytes_ += bytes;
  return {std::move(id), true};
}

std::shared_ptr<const ControlMesh> MeshCache::find(const std::string& id) {
  std::lock_guard lock(mutex_);
  auto it = byId_.find(id);
  if (it == byId_.end()) {
    ++misses_;
    return nullptr;
  }
  ++hits_;
  order_.splice(order_.begin(), order_, it->second);
  return it->second->mesh;
}

MeshCache::Counters MeshCache::counters() const {
  std::lock_guard lock(mutex_);
  return {hits_, misses_, evictions_, order_.size(), bytes_, capacityBytes_};
}

int MeshCache::facesOf(const std::string& id) const {
  std::lock_guard lock(mutex_);
  auto it = byId_.find(id);
  return it == byId_.end() ? -1 : it->second->mesh->faceCount();
}

}  // namespace limn::render::mesh
