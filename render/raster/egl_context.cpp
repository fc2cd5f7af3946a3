#include "render/raster/egl_context.h"

#include <EGL/eglext.h>

#include <cstdio>
#include <map>
#include <mutex>
#include <stdexcept>
#include <vector>

namespace limn::render::raster {

namespace {

std::string eglErrorText() {
  char buf[32];
  std::snprintf(buf, sizeof buf, "EGL error 0x%04X", static_cast<unsigned>(eglGetError()));
  return buf;
}

bool hasExtension(const char* list, const char* name) {
  if (!list) return false;
  std::string all = std::string(" ") + list + " ";
  return all.find(std::string(" ") + name + " ") != std::string::npos;
}

// EGL displays are per process and not reference counted: eglTerminate would pull the display
// from under every other context on it. Count the users here and terminate with the last.
std::mutex gDisplayMutex;
std::map<EGLDisplay, int> gDisplayUsers;

bool acquireDisplay(EGLDisplay display) {
  std::lock_guard<std::mutex> lock(gDisplayMutex);
  int& users = gDisplayUsers[display];
  if (users == 0 && !eglInitialize(display, nullptr, nullptr)) {
    gDisplayUsers.erase(display);
    return false;
  }
  ++users;
  return true;
}

void releaseDisplay(EGLDisplay display) {
  std::lock_guard<std::mutex> lock(gDisplayMutex);
  auto it = gDisplayUsers.find(display);
  if (it == gDisplayUsers.end()) return;
  if (--it->second == 0) {
    eglTerminate(display);
    gDisplayUsers.erase(it);
  }
}

// An OpenGL 4.5 core context without config or surface on an initialised display.
EGLContext createContext(EGLDisplay display, std::string& failure) {
  const char* extensions = eglQueryString(display, EGL_EXTENSIONS);
  if (!hasExtension(extensions, "EGL_KHR_no_config_context") &&
      !hasExtension(extensions, "EGL_MESA_configless_context")) {
    failure = "no EGL_KHR_no_config_context";
    return EGL_NO_CONTEXT;
  }
  if (!hasExtension(extensions, "EGL_KHR_surfaceless_context")) {
    failure = "no EGL_KHR_surfaceless_context";
    return EGL_NO_CONTEXT;
  }
  if (!eglBindAPI(EGL_OPENGL_API)) {
    failure = "eglBindAPI(EGL_OPENGL_API) failed: " + eglErrorText();
    return EGL_NO_CONTEXT;
  }
  const EGLint attributes[] = {EGL_CONTEXT_MAJOR_VERSION,
                               4,
                               EGL_CONTEXT_MINOR_VERSION,
                               5,
                               EGL_CONTEXT_OPENGL_PROFILE_MASK,
                               EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                               EGL_NONE};
  EGLContext context = eglCreateContext(display, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, attributes);
  if (context == EGL_NO_CONTEXT) {
    failure = "no OpenGL 4.5 core context: " + eglErrorText();
    return EGL_NO_CONTEXT;
  }
  if (!eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context)) {
    failure = "eglMakeCurrent failed: " + eglErrorText();
    eglDestroyContext(display, context);
    return EGL_NO_CONTEXT;
  }
  return context;
}

// Enumerated devices with hardware ones first: Mesa lists its software rasteriser as a device
// too, and the GPU should win where there is one.
std::vector<EGLDeviceEXT> devicesHardwareFirst() {
  auto queryDevices =
      reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
  auto queryDeviceString = reinterpret_cast<PFNEGLQUERYDEVICESTRINGEXTPROC>(
      eglGetProcAddress("eglQueryDeviceStringEXT"));
  if (!queryDevices) return {};
  EGLDeviceEXT devices[16];
  EGLint count = 0;
  if (!queryDevices(16, devices, &count)) return {};
  std::vector<EGLDeviceEXT> hardware, software;
  for (EGLint i = 0; i < count; ++i) {
    const char* extensions = queryDeviceString ? queryDeviceString(devices[i], EGL_EXTENSIONS) : "";
    (hasExtension(extensions, "EGL_MESA_device_software") ? software : hardware)
        .push_back(devices[i]);
  }
  hardware.insert(hardware.end(), software.begin(), software.end());
  return hardware;
}

}  // namespace

EglContext::EglContext() {
  const char* clientExtensions = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  std::string failures;
  auto tryDisplay = [&](EGLDisplay display, const char* platform, const std::string& label) {
    if (display == EGL_NO_DISPLAY || !acquireDisplay(display)) {
      failures += "\n  " + label + ": cannot initialise the display (" + eglErrorText() + ")";
      return false;
    }
    std::string failure;
    EGLContext context = createContext(display, failure);
    if (context == EGL_NO_CONTEXT) {
      failures += "\n  " + label + ": " + failure;
      releaseDisplay(display);
      return false;
    }
    display_ = display;
    context_ = context;
    platform_ = platform;
    return true;
  };

  if (hasExtension(clientExtensions, "EGL_EXT_platform_device")) {
    std::vector<EGLDeviceEXT> devices = devicesHardwareFirst();
    for (size_t i = 0; i < devices.size(); ++i) {
      EGLDisplay display = eglGetPlatformDisplay(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr);
      if (tryDisplay(display, "device", "EGL device " + std::to_string(i))) return;
    }
  } else {
    failures += "\n  EGL_EXT_platform_device is not supported";
  }
  if (hasExtension(clientExtensions, "EGL_MESA_platform_surfaceless")) {
    EGLDisplay display =
        eglGetPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    if (tryDisplay(display, "surfaceless", "surfaceless platform")) return;
  } else {
    failures += "\n  EGL_MESA_platform_surfaceless is not supported";
  }
  throw std::runtime_error("no headless OpenGL 4.5 core context could be created:" + failures);
}

EglContext::~EglContext() {
  if (isCurrent()) eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  eglDestroyContext(display_, context_);
  releaseDisplay(display_);
}

bool EglContext::isCurrent() const { return eglGetCurrentContext() == context_; }

void EglContext::makeCurrent() {
  if (isCurrent()) return;
  // The bound API is per thread state: bind it here too, in case this thread never did.
  if (!eglBindAPI(EGL_OPENGL_API) ||
      !eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_)) {
    throw std::runtime_error("cannot make the OpenGL context current: " + eglErrorText());
  }
}

}  // namespace limn::render::raster
