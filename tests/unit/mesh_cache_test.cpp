// MeshCache: content-addressed ids, least-recently-used eviction within a byte bound, and
// meshes that stay valid for whoever holds them after they are evicted.
#include "render/mesh/mesh_cache.h"

#include <gtest/gtest.h>

#include "render/mesh/content_hash.h"

namespace limn::render::mesh {
namespace {

// A fan of `n` triangles around vertex 0, shifted by `offset` so that each call can differ.
ControlMesh fan(int n, double offset = 0) {
  ControlMesh mesh;
  mesh.points.push_back({offset, 0, 0});
  for (int i = 0; i <= n; ++i) mesh.points.push_back({offset + i, 1, 0});
  for (int i = 0; i < n; ++i) {
    mesh.faceVertexCounts.push_back(3);
    mesh.faceVertexIndices.insert(mesh.faceVertexIndices.end(), {0, i + 1, i + 2});
  }
  return mesh;
}

TEST(MeshCache, IdIsTheContentHashAndFindsTheMesh) {
  MeshCache cache(1 << 20);
  const ControlMesh mesh = fan(4);
  MeshCache::Stored stored = cache.put(mesh);
  EXPECT_TRUE(stored.kept);
  EXPECT_EQ(stored.id, contentHash(mesh));
  EXPECT_EQ(cache.put(fan(4)).id, stored.id);  // the same mesh again: the same id, one entry
  EXPECT_EQ(cache.counters().entries, 1u);
  auto found = cache.find(stored.id);
  ASSERT_NE(found, nullptr);
  EXPECT_EQ(found->faceVertexIndices, mesh.faceVertexIndices);
  EXPECT_EQ(cache.find("not-an-id"), nullptr);
  EXPECT_EQ(cache.counters().hits, 1u);
  EXPECT_EQ(cache.counters().misses, 1u);
}

TEST(MeshCache, EvictsTheLeastRecentlyUsedWithinItsBound) {
  const size_t one = MeshCache::bytesOf(fan(10));
  MeshCache cache(3 * one + one / 2);  // room for three
  const std::string a = cache.put(fan(10, 0)).id, b = cache.put(fan(10, 1)).id;
  const std::string c = cache.put(fan(10, 2)).id;
  auto held = cache.find(a);  // a is now the most recently used; b the least
  const std::string d = cache.put(fan(10, 3)).id;
  EXPECT_EQ(cache.find(b), nullptr);
  EXPECT_NE(cache.find(a), nullptr);
  EXPECT_NE(cache.find(c), nullptr);
  EXPECT_NE(cache.find(d), nullptr);
  MeshCache::Counters counters = cache.counters();
  EXPECT_EQ(counters.entries, 3u);
  EXPECT_EQ(counters.evictions, 1u);
  EXPECT_LE(counters.bytes, counters.capacityBytes);

  // Evicting a mesh someone holds leaves their copy intact.
  for (int i = 4; i < 8; ++i) cache.put(fan(10, i));
  EXPECT_EQ(cache.find(a), nullptr);
  EXPECT_EQ(held->points.size(), 12u);
}

TEST(MeshCache, DoesNotKeepAMeshLargerThanItsBound) {
  MeshCache cache(MeshCache::bytesOf(fan(10)));
  MeshCache::Stored stored = cache.put(fan(1000));
  EXPECT_FALSE(stored.kept);
  EXPECT_EQ(cache.find(stored.id), nullptr);
  EXPECT_TRUE(cache.put(fan(10)).kept);
  EXPECT_FALSE(MeshCache(0).put(fan(1)).kept);
}

}  // namespace
}  // namespace limn::render::mesh
