// Rasterizer: headless OpenGL 4.5 core through EGL, drawing a TriangleMesh into an ImageSet.
//
// One Rasterizer per thread: the constructor creates an EGL display and context (device
// enumeration first, so a GPU is used where there is one; Mesa's surfaceless platform with
// llvmpipe otherwise) and makes it current on the calling thread. All rendering goes into
// framebuffer objects; no window or display server is involved. Construct it on the thread
// that will call render(), and destroy it there.
//
// What render() draws: every pass is point-sampled at pixel centres (no anti-aliasing), row 0
// at the top. Geometry outside the camera's near/far planes is clipped. Colour follows
// shading::shade() (back faces get the back albedo); the normal pass holds the shading normal
// as computed (not flipped for back faces); depth is linear (Camera::depthOf), 0 where empty.
// Frames larger than the GL limits, and supersampled masks, are drawn in tiles with the same
// sample positions. Shaders and GL objects are made once and reused; a mesh without normals is
// shaded flat. Bad input (indices out of range, normals not one per vertex, an empty image
// size) throws std::invalid_argument; GL failures throw std::runtime_error naming the step.
#pragma once

#include <memory>
#include <string>

#include "render/core/camera.h"
#include "render/core/image.h"
#include "render/core/passes.h"
#include "render/tessellate/triangle_mesh.h"

namespace limn::render::raster {

struct DeviceInfo {
  std::string renderer;  // GL_RENDERER, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"
  std::string vendor;    // GL_VENDOR
  std::string version;   // GL_VERSION
  std::string eglPlatform;  // "device" or "surfaceless"
};

class Rasterizer {
 public:
  Rasterizer();  // throws std::runtime_error when no EGL/OpenGL 4.5 context can be made
  ~Rasterizer();
  Rasterizer(const Rasterizer&) = delete;
  Rasterizer& operator=(const Rasterizer&) = delete;

  const DeviceInfo& device() const;

  // Draws `mesh` for `camera` and returns the selected passes at the camera's size, plus the
  // supersampled coverage mask when passes.supersample > 0. Shading follows render/core/shading.h.
  ImageSet render(const tessellate::TriangleMesh& mesh, const Camera& camera,
                  const PassSelection& passes, Shading shading);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace limn::render::raster
