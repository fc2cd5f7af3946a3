// EglContext: one headless OpenGL 4.5 core context, owned by one thread.
//
// The display is found by EGL device enumeration first (so a GPU is used where there is one,
// software devices last), then Mesa's surfaceless platform. The context has no config and no
// surface (EGL_NO_CONFIG_KHR, EGL_NO_SURFACE): everything is drawn into framebuffer objects.
// Displays are shared by all contexts of the process and terminated when the last one goes.
#pragma once

#include <EGL/egl.h>

#include <string>

namespace limn::render::raster {

class EglContext {
 public:
  EglContext();  // creates the context and makes it current; throws std::runtime_error
  ~EglContext();
  EglContext(const EglContext&) = delete;
  EglContext& operator=(const EglContext&) = delete;

  // Makes this context current on the calling thread (cheap when it already is).
  void makeCurrent();
  bool isCurrent() const;

  // "device" or "surfaceless": how the display was obtained.
  const std::string& platform() const { return platform_; }

 private:
  EGLDisplay display_ = EGL_NO_DISPLAY;
  EGLContext context_ = EGL_NO_CONTEXT;
  std::string platform_;
};

}  // namespace limn::render::raster
