#include "render/mesh/content_hash.h"

#include <xxhash.h>

#include <cstdio>
#include <memory>
#include <stdexcept>
#include <vector>

namespace limn::render::mesh {

namespace {

// Streams fields into XXH3-128 one by one (no struct padding is ever hashed); vectors are
// prefixed with their length so that moving an element from one list to the next changes the
// digest.
class Digest {
 public:
  Digest() : state_(XXH3_createState(), XXH3_freeState) {
    if (!state_ || XXH3_128bits_reset(state_.get()) != XXH_OK) {
      throw std::runtime_error("xxhash: cannot initialise");
    }
  }
  template <typename T>
  void add(const T& value) {
    XXH3_128bits_update(state_.get(), &value, sizeof(T));
  }
  template <typename T>
  void addVector(const std::vector<T>& values) {
    add(values.size());
    if (!values.empty())
      XXH3_128bits_update(state_.get(), values.data(), values.size() * sizeof(T));
  }
  std::string hex() const {
    XXH128_hash_t h = XXH3_128bits_digest(state_.get());
    char text[33];
    std::snprintf(text, sizeof text, "%016llx%016llx", static_cast<unsigned long long>(h.high64),
                  static_cast<unsigned long long>(h.low64));
    return text;
  }

 private:
  std::unique_ptr<XXH3_state_t, XXH_errorcode (*)(XXH3_state_t*)> state_;
};

}  // namespace

std::string contentHash(const ControlMesh& m) {
  Digest d;
  d.add(static_cast<int>(m.scheme));
  d.add(static_cast<int>(m.boundary));
  d.add(static_cast<int>(m.creaseMethod));
  d.add(static_cast<int>(m.triangleSubdivision));
  d.add(m.points.size());
  for (const Vec3& p : m.points) {
    d.add(p.x);
    d.add(p.y);
    d.add(p.z);
  }
  d.addVector(m.faceVertexCounts);
  d.addVector(m.faceVertexIndices);
  d.add(m.creases.size());
  for (const Crease& c : m.creases) {
    d.add(c.v0);
    d.add(c.v1);
    d.add(c.sharpness);
  }
  d.add(m.corners.size());
  for (const Corner& c : m.corners) {
    d.add(c.vertex);
    d.add(c.sharpness);
  }
  d.addVector(m.holes);
  return d.hex();
}

}  // namespace limn::render::mesh
