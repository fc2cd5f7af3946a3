#include "render/oracle/reference_scene.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
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

// Output pixels the outline of the tessellation may cross (see renderReference in reference.h):
// the screen bounding boxes of every triangle whose geometric facing differs from the facing of
// one of its vertex normals, or whose vertex normals disagree, and of every triangle of a face
// on a border. The coverage of a triangle mesh changes only across an edge between a front- and
// a back-facing triangle, or across a boundary edge, and at least one triangle at each such
// edge is marked: so a thin spike or sliver between pixel centres is not missed.
std::vector<char> outlineCandidates(const ReferenceTessellation& tessellation,
                                    const Camera& camera) {
  const tessellate::TriangleMesh& mesh = tessellation.mesh;
  const int width = camera.width(), height = camera.height();
  std::vector<char> marked(static_cast<size_t>(width) * height, 0);
  auto toVec3 = [](const Vec3f& v) { return Vec3{v.x, v.y, v.z}; };
  tbb::parallel_for(
      tbb::blocked_range<size_t>(0, mesh.triangleCount(), 4096),
      [&](const tbb::blocked_range<size_t>& r) {
        for (size_t t = r.begin(); t < r.end(); ++t) {
          const uint32_t* v = &mesh.indices[3 * t];
          Vec3 p[3] = {toVec3(mesh.positions[v[0]]), toVec3(mesh.positions[v[1]]),
                       toVec3(mesh.positions[v[2]])};
          bool candidate = tessellation.borderFaces[mesh.triangleFaces[t]] != 0;
          if (!candidate) {
            Vec3 centroid = (p[0] + p[1] + p[2]) * (1.0 / 3.0);
            bool facing = dot(cross(p[1] - p[0], p[2] - p[0]), camera.viewVector(centroid)) < 0;
            for (int k = 0; k < 3 && !candidate; ++k) {
              bool vertexFacing = dot(toVec3(mesh.normals[v[k]]), camera.viewVector(p[k])) < 0;
              candidate = vertexFacing != facing;
            }
          }
          if (!candidate) continue;
          double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
          for (const Vec3& q : p) {
            Vec3 s = camera.project(q);
            x0 = std::min(x0, s.x), y0 = std::min(y0, s.y), x1 = std::max(x1, s.x),
            y1 = std::max(y1, s.y);
          }
          int i0 = std::max(0, static_cast<int>(std::floor(x0))),
              j0 = std::max(0, static_cast<int>(std::floor(y0)));
          int i1 = std::min(width - 1, static_cast<int>(std::floor(x1))),
              j1 = std::min(height - 1, static_cast<int>(std::floor(y1)));
          for (int j = j0; j <= j1; ++j) {
            for (int i = i0; i <= i1; ++i) {
              std::atomic_ref<char>(marked[static_cast<size_t>(j) * width + i])
                  .store(1, std::memory_order_relaxed);
            }
          }
        }
      });
  return marked;
}

}  // namespace

std::shared_ptr<const ReferenceScene> buildReferenceScene(const subdiv::LimitSurface& surface,
                                                          const Camera& camera,
                                                          const CancelToken& cancel,
                                                          double triangleBudget) {
  auto scene = std::make_shared<ReferenceScene>();
  auto start = std::chrono::steady_clock::now();
  scene->tessellation = tessellateForReference(surface, camera, cancel, triangleBudget);
  scene->tessellateMs = msSince(start);
  cancel.check();
  start = std::chrono::steady_clock::now();
  // LOW: the reference casts about one ray per pixel plus a few per outline pixel, too few for a
  // slower, better BVH to pay off (triangle_scene.h has the measurements).
  scene->scene = buildTriangleScene(scene->tessellation.mesh, RTC_BUILD_QUALITY_LOW);
  scene->bvhMs = msSince(start);
  scene->outlineCandidates = outlineCandidates(scene->tessellation, camera);
  scene->bytes = estimateBytes(scene->tessellation.mesh) + scene->outlineCandidates.size();
  return scene;
}

std::string referenceSceneKey(const subdiv::LimitSurface& surface, const Camera& c,
                              double triangleBudget) {
  char view[512];
  std::snprintf(view, sizeof view,
                "|%.17g,%.17g,%.17g|%.17g,%.17g,%.17g|%.17g,%.17g,%.17g|%.17g|%d|%.17g|%dx%d|%.17g,"
                "%.17g|%.17g",
                c.eye().x, c.eye().y, c.eye().z, c.target().x, c.target().y, c.target().z, c.up().x,
                c.up().y, c.up().z, c.fovYDeg(), static_cast<int>(c.projection()), c.orthoHeight(),
                c.width(), c.height(), c.nearPlane(), c.farPlane(), triangleBudget);
  return mesh::contentHash(surface.mesh()) + "|" + surface.displacementSpec().key() + view;
}

std::shared_ptr<const ReferenceScene> ReferenceSceneCache::get(const subdiv::LimitSurface& surface,
                                                               const Camera& camera,
                                                               const CancelToken& cancel, bool* hit,
                                                               double triangleBudget) {
  const std::string key = referenceSceneKey(surface, camera, triangleBudget);
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
  std::shared_ptr<const ReferenceScene> scene =
      buildReferenceScene(surface, camera, cancel, triangleBudget);
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
