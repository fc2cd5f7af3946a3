// The process's Embree device and the small rules every Embree caller in limn follows.
//
// One RTCDevice serves the whole process (created on first use, never released: Embree's
// device owns thread-local state and its TBB arena, and recreating it per request costs
// milliseconds). Scenes are made per request. Every thread that traces rays or builds a BVH must
// flush denormals to zero (Embree's kernels assume FTZ/DAZ); FlushDenormalsScope sets that for
// the lifetime of a task and restores the caller's mode afterwards.
#pragma once

#include <embree3/rtcore.h>

#include <string>

namespace limn::render::oracle {

// The shared device. Thread-safe.
RTCDevice embreeDevice();

// Embree's last error on this thread since the previous call, as "code: message", or "" when
// there was none. Clears it.
std::string takeEmbreeError();

// Throws std::runtime_error("Embree <what>: <error>") when the device holds an error.
void checkEmbree(const char* what);

// Sets FTZ and DAZ in this thread's MXCSR while alive.
class FlushDenormalsScope {
 public:
  FlushDenormalsScope();
  ~FlushDenormalsScope();
  FlushDenormalsScope(const FlushDenormalsScope&) = delete;
  FlushDenormalsScope& operator=(const FlushDenormalsScope&) = delete;

 private:
  unsigned int savedCsr_;
};

// An owned RTCScene (released on destruction).
class EmbreeScene {
 public:
  EmbreeScene() = default;
  explicit EmbreeScene(RTCScene scene) : scene_(scene) {}
  ~EmbreeScene();
  EmbreeScene(EmbreeScene&& other) noexcept : scene_(other.scene_) { other.scene_ = nullptr; }
  EmbreeScene& operator=(EmbreeScene&& other) noexcept;
  EmbreeScene(const EmbreeScene&) = delete;
  EmbreeScene& operator=(const EmbreeScene&) = delete;

  RTCScene get() const { return scene_; }

 private:
  RTCScene scene_ = nullptr;
};

}  // namespace limn::render::oracle
