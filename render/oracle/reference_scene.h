// ReferenceScene: the part of the reference that depends only on the mesh and the camera — the
// dense tessellation and its Embree BVH — and ReferenceSceneCache, a byte-bounded LRU of them.
//
// The tessellation is view-dependent (finer where the outline is, reference_tessellation.h), so
// a scene serves one (mesh, camera) pair: every further request for the same view — another
// method, other outputs or supersampling, the reference cross-check, a comparison of methods —
// skips about 40% of the reference's time. The cache is shared by all workers (thread-safe);
// entries are shared_ptrs, so an evicted scene lives on until its last user lets go. Two
// workers missing the same key at once both build it (the second insert wins); nothing waits
// on another request's build.
#pragma once

#include <cstddef>
#include <list>
#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>
#include <vector>

#include "render/core/camera.h"
#include "render/core/cancel.h"
#include "render/oracle/embree_device.h"
#include "render/oracle/reference_tessellation.h"
#include "render/subdiv/limit_surface.h"

namespace limn::render::oracle {

struct ReferenceScene {
  ReferenceTessellation tessellation;
  EmbreeScene scene;
  // Per output pixel: the tessellation's outline may cross it (reference.cpp casts the
  // supersampled mask there); a property of the mesh and the view, so cached with them.
  std::vector<char> outlineCandidates;
  double tessellateMs = 0, bvhMs = 0;  // what building it cost
  size_t bytes = 0;                    // estimated memory: mesh arrays + Embree's BVH
};

std::shared_ptr<const ReferenceScene> buildReferenceScene(
    const subdiv::LimitSurface& surface, const Camera& camera, const CancelToken& cancel,
    double triangleBudget = kReferenceTriangleBudget);

// The cache key: the mesh's content hash, its displacement, every camera parameter and the
// triangle budget.
std::string referenceSceneKey(const subdiv::LimitSurface& surface, const Camera& camera,
                              double triangleBudget = kReferenceTriangleBudget);

class ReferenceSceneCache {
 public:
  // 0 bytes: nothing is kept (every get builds).
  explicit ReferenceSceneCache(size_t capacityBytes) : capacity_(capacityBytes) {}

  // The scene of `surface` seen by `camera`, built when missing; *hit says which.
  std::shared_ptr<const ReferenceScene> get(const subdiv::LimitSurface& surface,
                                            const Camera& camera, const CancelToken& cancel,
                                            bool* hit,
                                            double triangleBudget = kReferenceTriangleBudget);

  struct Counters {
    size_t hits = 0, misses = 0, evictions = 0, entries = 0, bytes = 0, capacityBytes = 0;
  };
  Counters counters() const;
  void clear();

 private:
  using Entry = std::pair<std::string, std::shared_ptr<const ReferenceScene>>;
  void insertLocked(const std::string& key, std::shared_ptr<const ReferenceScene> scene);

  const size_t capacity_;
  mutable std::mutex mutex_;
  std::list<Entry> lru_;  // most recently used first
  std::unordered_map<std::string, std::list<Entry>::iterator> index_;
  size_t bytes_ = 0, hits_ = 0, misses_ = 0, evictions_ = 0;
};

}  // namespace limn::render::oracle
