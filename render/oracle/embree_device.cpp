#include "render/oracle/embree_device.h"

#include <pmmintrin.h>  // DAZ (SSE3)
#include <xmmintrin.h>  // FTZ

#include <stdexcept>

namespace limn::render::oracle {

namespace {

// Embree reports errors through a callback, called on the thread whose API call failed (errors
// inside a parallel build surface at the call that started it). The message is kept per thread,
// so concurrent requests sharing the device each see their own, and a caller can say what
// Embree objected to.
thread_local std::string lastError;

const char* errorName(RTCError code) {
  switch (code) {
    case RTC_ERROR_NONE:
      return "none";
    case RTC_ERROR_UNKNOWN:
      return "unknown error";
    case RTC_ERROR_INVALID_ARGUMENT:
      return "invalid argument";
    case RTC_ERROR_INVALID_OPERATION:
      return "invalid operation";
    case RTC_ERROR_OUT_OF_MEMORY:
      return "out of memory";
    case RTC_ERROR_UNSUPPORTED_CPU:
      return "unsupported CPU";
    case RTC_ERROR_CANCELLED:
      return "cancelled";
  }
  return "error";
}

void recordError(void*, RTCError code, const char* message) {
  if (lastError.empty()) {
    lastError = std::string(errorName(code)) + (message ? std::string(": ") + message : "");
  }
}

}  // namespace

RTCDevice embreeDevice() {
  static RTCDevice device = [] {
    // "" = Embree's defaults: all hardware threads through TBB, best ISA for this CPU.
    RTCDevice d = rtcNewDevice("");
    if (!d) throw std::runtime_error("Embree: rtcNewDevice failed");
    rtcSetDeviceErrorFunction(d, recordError, nullptr);
    return d;
  }();
  return device;
}

std::string takeEmbreeError() {
  RTCError code = rtcGetDeviceError(embreeDevice());
  std::string message = std::move(lastError);
  lastError.clear();
  if (message.empty() && code != RTC_ERROR_NONE) message = errorName(code);
  return message;
}

void checkEmbree(const char* what) {
  std::string error = takeEmbreeError();
  if (!error.empty()) throw std::runtime_error(std::string("Embree ") + what + ": " + error);
}

FlushDenormalsScope::FlushDenormalsScope() : savedCsr_(_mm_getcsr()) {
  _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
  _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
}

FlushDenormalsScope::~FlushDenormalsScope() { _mm_setcsr(savedCsr_); }

EmbreeScene::~EmbreeScene() {
  if (scene_) rtcReleaseScene(scene_);
}

EmbreeScene& EmbreeScene::operator=(EmbreeScene&& other) noexcept {
  if (this != &other) {
    if (scene_) rtcReleaseScene(scene_);
    scene_ = other.scene_;
    other.scene_ = nullptr;
  }
  return *this;
}

}  // namespace limn::render::oracle
