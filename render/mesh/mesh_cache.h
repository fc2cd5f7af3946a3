// MeshCache: control meshes a client uploaded once (POST /v1/meshes) and refers to by id in
// later requests, so that orbiting a large mesh does not resend it with every frame.
//
// The id is the mesh's contentHash(): the same mesh uploaded twice gets the same id, and an id
// says nothing about who uploaded it. The cache is bounded by an estimate of the bytes its
// meshes hold; when a new mesh would go over, the least recently used ones are evicted (a
// lookup counts as a use). A mesh larger than the whole capacity is not kept. The server owns
// one and shares it between its threads: every member is thread-safe. Meshes come back as
// shared pointers, so an eviction never pulls one from under a request that holds it.
#pragma once

#include <cstddef>
#include <list>
#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>

#include "render/mesh/control_mesh.h"

namespace limn::render::mesh {

class MeshCache {
 public:
  explicit MeshCache(size_t capacityBytes) : capacityBytes_(capacityBytes) {}

  struct Stored {
    std::string id;
    bool kept = false;  // false: larger than the whole cache (or capacity 0)
  };
  // Keeps `mesh` under its content hash (refreshing it when it is there already).
  Stored put(ControlMesh mesh);
  // The mesh with this id, or null when it was never stored or has been evicted.
  std::shared_ptr<const ControlMesh> find(const std::string& id);
  // The face count of the mesh with this id, or -1: a look that neither counts as a lookup nor
  // refreshes the mesh (the scheduler's estimate of a request, before it runs).
  int facesOf(const std::string& id) const;

  struct Counters {
    size_t hits = 0, misses = 0, evictions = 0, entries = 0, bytes = 0, capacityBytes = 0;
  };
  Counters counters() const;

  // The estimate the bound uses: the mesh's arrays.
  static size_t bytesOf(const ControlMesh& mesh);

 private:
  struct Entry {
    std::string id;
    std::shared_ptr<const ControlMesh> mesh;
    size_t bytes;
  };
  using Order = std::list<Entry>;  // most recently used first

  mutable std::mutex mutex_;
  size_t capacityBytes_;
  size_t bytes_ = 0;
  Order order_;
  std::unordered_map<std::string, Order::iterator> byId_;
  size_t hits_ = 0, misses_ = 0, evictions_ = 0;
};

}  // namespace limn::render::mesh
