// Rasterizer: headless OpenGL 4.5 core through EGL, drawing a TriangleMesh into an ImageSet.
//
// One Rasterizer per thread: the constructor creates an EGL display and context (device
// enumeration first, so a GPU is used where there is one; Mesa's surfaceless platform with
// llvmpipe otherwise) and makes it current on the calling thread. All rendering goes into
// framebuffer objects; no window or display server is involved. Construct it on the thread
// that will call render(), and destroy it there.
//
// What render() draws: every pass is point-sampled at pixel centres, row 0 at the top, except
// that with passes.antialias > 1 the colour, wireframe and overlay passes are multisampled
// (MSAA, shaded once per pixel and triangle, covered at each sample) and resolved to the mean
// of each pixel's samples. Geometry outside the camera's near/far planes is clipped. Colour follows
// shading::shade(), the side being the triangle's winding (back faces get the back albedo; a
// smooth normal that turns away on a front face gets no light), and back faces are drawn
// behind front faces where their depths tie; the normal pass holds the shading normal
// as computed (not flipped for back faces); depth is linear (Camera::depthOf), 0 where empty.
// Line overlays (render/core/overlay.h) each make one more pass: the colour image with the
// overlay's segments drawn over it, 2 px wide with square ends, composited with their alpha.
// Occluded overlays are depth-tested against the surface with a bias (lines are moved 1 px
// towards the eye, the surface pushed back by twice its depth slope), so lines lying on it
// stay visible; the others are drawn over everything.
// Frames larger than the GL limits, and supersampled masks, are drawn in tiles with the same
// sample positions. Shaders and GL objects are made once and reused; a mesh without normals is
// shaded flat. Shading::NormalMap takes each pixel's normal from mesh.normalMap, sampled
// bilinearly (no mipmaps, clamped to the edge) at the interpolated mesh.texcoords and
// renormalised; it needs both (texcoords one per vertex) and a map no larger than
// device().maxTextureSize, which is uploaded for every render. Bad input (indices out of
// range, normals or texcoords not one per vertex, an empty image size, a malformed overlay: see
// validateOverlays in overlay_buffers.h, normal-map shading without a map) throws
// std::invalid_argument; GL failures throw std::runtime_error naming the step.
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "render/core/camera.h"
#include "render/core/cancel.h"
#include "render/core/image.h"
#include "render/core/overlay.h"
#include "render/core/passes.h"
#include "render/tessellate/triangle_mesh.h"

namespace limn::render::raster {

struct DeviceInfo {
  std::string renderer;     // GL_RENDERER, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"
  std::string vendor;       // GL_VENDOR
  std::string version;      // GL_VERSION
  std::string eglPlatform;  // "device" or "surfaceless"
  int maxTextureSize = 0;   // GL_MAX_TEXTURE_SIZE: the largest normal map side it can take
  int maxSamples = 0;       // GL_MAX_SAMPLES: the most samples per pixel it draws
};

class Rasterizer {
 public:
  Rasterizer();  // throws std::runtime_error when no EGL/OpenGL 4.5 context can be made
  ~Rasterizer();
  Rasterizer(const Rasterizer&) = delete;
  Rasterizer& operator=(const Rasterizer&) = delete;

  const DeviceInfo& device() const;
  // Makes its context current on the calling thread, for GL work of other modules between
  // renders (the patches' tessellation shaders); render() does it itself.
  void makeCurrent();

  // The samples per pixel render() draws for passes.antialias = `samples`: as many, or the most
  // the device takes (device().maxSamples; llvmpipe's is 4).
  int samplesTaken(int samples) const;
  // Where those samples lie within the pixel: x right, y down, in [0, 1]; the pixel centre for
  // one. The reference casts its colour rays there, so that both pictures average the same
  // points.
  std::vector<std::array<float, 2>> samplePositions(int samples);

  // Draws `mesh` for `camera` and returns the selected passes at the camera's size, plus the
  // supersampled coverage mask when passes.supersample > 0, plus one pass per overlay, named
  // overlay.pass. Shading follows render/core/shading.h. `cancel` is checked before each tile
  // (a 4096^2 mask supersampled 8 times is 1,024 tiles and about ten seconds on llvmpipe).
  ImageSet render(const tessellate::TriangleMesh& mesh, const Camera& camera,
                  const PassSelection& passes, Shading shading,
                  const std::vector<LineOverlay>& overlays = {},
                  const CancelToken& cancel = CancelToken{});

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace limn::render::raster
