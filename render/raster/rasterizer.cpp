#include "render/raster/rasterizer.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "render/core/huge_pages.h"
#include "render/core/parallel.h"
#include "render/core/shading.h"
#include "render/raster/egl_context.h"
#include "render/raster/framebuffer.h"
#include "render/raster/gl_api.h"
#include "render/raster/gl_error.h"
#include "render/raster/mesh_buffers.h"
#include "render/raster/normal_texture.h"
#include "render/raster/overlay_buffers.h"
#include "render/raster/shader_program.h"
#include "render/raster/shaders.h"
#include "render/raster/tiling.h"

namespace limn::render::raster {

namespace {

// Largest tile of each framebuffer, besides the GL limits: the frame pass holds 44 bytes per
// pixel (2048^2: 176 MiB), the coverage pass 1 byte per pixel (4096^2: 16 MiB).
constexpr int kFrameTileCap = 2048;
constexpr int kCoverageTileCap = 4096;
// Samples of one tile of the anti-aliased colour pass (12 bytes each: colour, overlay, depth):
// 8M, 96 MiB, i.e. 1448^2 at 4 samples per pixel, 1024^2 at 8, 724^2 at 16.
constexpr double kMultisampleTileSamples = 8 << 20;

// Attachments of the frame pass; fragment output i writes attachment i.
enum FrameAttachment {
  kColorAttachment = 0,
  kDepthAttachment = 1,
  kNormalAttachment = 2,
  kOverlayAttachment = 3,  // one overlay's lines at a time, RGBA8, transparent where none
};

// Overlay lines are 2 px wide, and moved 1 px (the world size of one pixel at their depth)
// towards the eye, so lines on a surface, or on the limit surface a little behind its
// tessellation, are not hidden by it.
constexpr float kOverlayHalfWidthPx = 1.0f;
constexpr double kOverlayBiasPx = 1.0;
// Polygon offset of the surface when edges or lines are drawn over it, in units of its depth
// slope per pixel: lines lying on a surface still pass the depth test a line half-width
// (1 px, up to sqrt(2) times the slope diagonally) to either side of their centre.
constexpr float kSurfaceOffset = -2.0f;
// How much further back-facing triangles are pushed, in the same units: where a front face and
// a back face meet at the outline of a closed surface their depths tie or nearly tie, and the
// back face must not win (it would show the back albedo along the outline).
constexpr float kBackFaceOffset = -2.0f;

constexpr float kBackgroundColor[4] = {shading::kBackground[0], shading::kBackground[1],
                                       shading::kBackground[2], 0.0f};
constexpr float kWireColor[4] = {shading::kWireColor[0], shading::kWireColor[1],
                                 shading::kWireColor[2], 1.0f};

std::string glString(GLenum name) {
  const GLubyte* text = glGetString(name);
  return text ? reinterpret_cast<const char*>(text) : "";
}

int largestFramebufferSide() {
  GLint renderbuffer = 0, viewport[2] = {0, 0}, fbWidth = 0, fbHeight = 0;
  glGetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &renderbuffer);
  glGetIntegerv(GL_MAX_VIEWPORT_DIMS, viewport);
  glGetIntegerv(GL_MAX_FRAMEBUFFER_WIDTH, &fbWidth);
  glGetIntegerv(GL_MAX_FRAMEBUFFER_HEIGHT, &fbHeight);
  checkGl("querying the framebuffer limits");
  return std::min({renderbuffer, viewport[0], viewport[1], fbWidth, fbHeight});
}

// Copies a tile read back from OpenGL (bottom row first, `srcComponents` values per pixel)
// into its place in `dst` (an Image or a Mask, top row first), through
// `convert(const T* src, pixel* dst)`.
template <typename T, typename Destination, typename Convert>
void placeTile(const std::vector<T>& src, int srcComponents, const Tile& tile, Destination& dst,
               Convert convert) {
  for (int r = 0; r < tile.height; ++r) {
    const int dstRow = tile.y + tile.height - 1 - r;
    for (int i = 0; i < tile.width; ++i) {
      const T* from = &src[(static_cast<size_t>(r) * tile.width + i) * srcComponents];
      convert(from, &dst.at(tile.x + i, dstRow));
    }
  }
}

// placeTile for the coverage pass (bytes 255 where covered, 0 not), into a mask of 1s and 0s,
// its rows in parallel: a 4096^2 tile is 16 MiB, and the loop below vectorises where
// placeTile's per-pixel call does not.
void placeCoverageTile(const std::vector<unsigned char>& src, const Tile& tile, Mask& dst) {
  parallelFor(tile.height, 64, [&](size_t begin, size_t end) {
    for (size_t r = begin; r < end; ++r) {
      const unsigned char* from = &src[r * tile.width];
      uint8_t* to = &dst.at(tile.x, tile.y + tile.height - 1 - static_cast<int>(r));
      for (int i = 0; i < tile.width; ++i) to[i] = from[i] >> 7;
    }
  });
}

template <int N>
void copyComponents(const float* from, float* to) {
  std::copy(from, from + N, to);
}

// Composites a tile of overlay lines (RGBA bytes) over the colour tile (RGBA floats), both
// bottom row first, into `dst`: "over" with the line's alpha; exactly the colour where no line.
void placeOverlayTile(const std::vector<float>& color, const std::vector<unsigned char>& lines,
                      const Tile& tile, Image& dst) {
  for (int r = 0; r < tile.height; ++r) {
    const int dstRow = tile.y + tile.height - 1 - r;
    for (int i = 0; i < tile.width; ++i) {
      const size_t at = (static_cast<size_t>(r) * tile.width + i) * 4;
      const float* c = &color[at];
      const unsigned char* line = &lines[at];
      float* to = &dst.at(tile.x + i, dstRow, 0);
      const float a = line[3] / 255.0f;
      for (int k = 0; k < 3; ++k) to[k] = a * (line[k] / 255.0f) + (1.0f - a) * c[k];
      to[3] = a + (1.0f - a) * c[3];
    }
  }
}

// True when no vertex of `mesh` is behind the camera's near plane: a closed surface that the
// near plane does not cut cannot hold the eye (nor, orthographic, any ray's start).
bool inFrontOfNearPlane(const tessellate::TriangleMesh& mesh, const Camera& camera) {
  for (const Vec3f& p : mesh.positions) {
    if (camera.depthOf(Vec3(p.x, p.y, p.z)) <= camera.nearPlane()) return false;
  }
  return true;
}

}  // namespace

struct Rasterizer::Impl {
  EglContext context;  // first: everything below needs it current
  DeviceInfo device;
  ShaderProgram surfaceProgram{"surface", surfaceVertexShader(), surfaceFragmentShader()};
  ShaderProgram solidProgram{"solid", solidVertexShader(), solidFragmentShader()};
  ShaderProgram lineProgram{"line", lineVertexShader(), lineFragmentShader(), lineGeometryShader()};
  MeshBuffers mesh;
  NormalTexture normalTexture;
  OverlayBuffers overlayLines;
  Framebuffer frame{{GL_RGBA32F, GL_R32F, GL_RGBA32F, GL_RGBA8}, /*withDepth=*/true};
  // The anti-aliased colour and overlay (attachments as frame's), and their resolved pixels.
  Framebuffer multisampled{{GL_RGBA8, GL_NONE, GL_NONE, GL_RGBA8}, /*withDepth=*/true};
  Framebuffer resolved{{GL_RGBA8, GL_RGBA8}, /*withDepth=*/false};
  Framebuffer coverage{{GL_R8}, /*withDepth=*/false};
  int frameTileSize = 0;
  int coverageTileSize = 0;
  bool backFacesHidden = false;  // of the mesh being drawn (see render())
  std::vector<float> readback;
  std::vector<float> colorReadback;  // kept while overlays are drawn over it
  std::vector<unsigned char> readbackBytes;

  Impl();
  ~Impl();
  void renderFrame(const Camera& camera, const PassSelection& passes, Shading shading,
                   const std::vector<LineOverlay>& overlays, const CancelToken& cancel,
                   ImageSet& out);
  void drawSurface(bool offsetSurface);
  void drawSingleSample(const Tile& tile, const PassSelection& passes, bool offsetSurface,
                        bool colorBuffer, bool antialiased, Image& color, Image& mask, Image& depth,
                        Image& normal);
  void drawLines(const LineOverlay& overlay, size_t k, Framebuffer& target);
  void drawAntialiased(const Tile& tile, const PassSelection& passes, bool offsetSurface,
                       const std::vector<LineOverlay>& overlays, Image& color, Image& wireframe,
                       std::vector<Image>& overlayImages);
  void setLineUniforms(const Camera& camera);
  void renderCoverage(const Camera& camera, int supersample, const CancelToken& cancel,
                      ImageSet& out);
};

Rasterizer::Impl::Impl() {
  device.renderer = glString(GL_RENDERER);
  device.vendor = glString(GL_VENDOR);
  device.version = glString(GL_VERSION);
  device.eglPlatform = context.platform();
  device.maxTextureSize = normalTexture.maxSide();
  glGetIntegerv(GL_MAX_SAMPLES, &device.maxSamples);

  const int largest = largestFramebufferSide();
  frameTileSize = std::min(largest, kFrameTileCap);
  coverageTileSize = std::min(largest, kCoverageTileCap);

  // Fixed state for all passes: reversed float depth (see tiling.h), no dithering, no
  // multisampling, no culling (back faces are drawn, after the front faces, and shaded with
  // the back albedo; drawSurface() culls each side in turn).
  glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
  glDisable(GL_DITHER);
  glDisable(GL_MULTISAMPLE);
  glDisable(GL_CULL_FACE);
  glFrontFace(GL_CCW);
  checkGl("setting up the OpenGL context");
}

Rasterizer::Impl::~Impl() {
  // GL objects are deleted by the members' destructors, which need the context current.
  try {
    context.makeCurrent();
  } catch (const std::exception&) {
    // Nothing to do: without the context its objects go with it.
  }
}

void Rasterizer::Impl::drawSurface(bool offsetSurface) {
  // Front faces, then back faces pushed back a little, so that back faces lose depth ties.
  // When lines are drawn over it the whole surface is pushed back too, so that edges lying on
  // it pass the depth test while edges behind other surfaces still fail it.
  const float front = offsetSurface ? kSurfaceOffset : 0.0f;
  glEnable(GL_CULL_FACE);
  glEnable(GL_POLYGON_OFFSET_FILL);
  glCullFace(GL_BACK);
  glPolygonOffset(front, front);
  mesh.drawTriangles();
  if (backFacesHidden) {
    // A closed surface seen from outside: every back face is behind a front face. The second
    // draw cost llvmpipe a quarter of a small request (bench/load_results.md).
    glDisable(GL_POLYGON_OFFSET_FILL);
    glDisable(GL_CULL_FACE);
    return;
  }
  glCullFace(GL_FRONT);
  glPolygonOffset(front + kBackFaceOffset, front + kBackFaceOffset);
  mesh.drawTriangles();
  glDisable(GL_POLYGON_OFFSET_FILL);
  glDisable(GL_CULL_FACE);
}

void Rasterizer::Impl::drawLines(const LineOverlay& overlay, size_t k, Framebuffer& target) {
  const float transparent[4] = {0, 0, 0, 0};
  target.setDrawBuffers({false, false, false, true});
  target.clearColor(kOverlayAttachment, transparent);
  if (overlay.occluded) {
    glEnable(GL_DEPTH_TEST);
  } else {
    glDisable(GL_DEPTH_TEST);
  }
  lineProgram.use();
  overlayLines.draw(k);
  checkGl("drawing an overlay");
}

// The colour-like passes of one tile, multisampled at passes.antialias samples per pixel and
// resolved (each pixel the mean of its samples): the surface, each overlay over it, the
// wireframe. The programs' uniforms for the tile are set.
void Rasterizer::Impl::drawAntialiased(const Tile& tile, const PassSelection& passes,
                                       bool offsetSurface, const std::vector<LineOverlay>& overlays,
                                       Image& color, Image& wireframe,
                                       std::vector<Image>& overlayImages) {
  resolved.bind(tile.width, tile.height);  // sized; the draws go to `multisampled`
  multisampled.bind(tile.width, tile.height, passes.antialias);
  multisampled.setDrawBuffers({true});
  multisampled.clearColor(kColorAttachment, kBackgroundColor);
  multisampled.clearDepth(0.0f);
  glEnable(GL_MULTISAMPLE);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_GREATER);
  glDepthMask(GL_TRUE);
  surfaceProgram.use();
  drawSurface(offsetSurface);
  checkGl("drawing the anti-aliased surface");
  multisampled.resolveInto(kColorAttachment, resolved, 0);
  resolved.read(0, GL_RGBA, colorReadback);
  if (passes.color) placeTile(colorReadback, 4, tile, color, copyComponents<4>);

  glDepthMask(GL_FALSE);
  glDepthFunc(GL_GEQUAL);
  for (size_t k = 0; k < overlays.size(); ++k) {
    drawLines(overlays[k], k, multisampled);
    multisampled.resolveInto(kOverlayAttachment, resolved, 1);
    resolved.readBytes(1, GL_RGBA, readbackBytes);
    placeOverlayTile(colorReadback, readbackBytes, tile, overlayImages[k]);
  }
  if (passes.wireframe) {
    multisampled.setDrawBuffers({true});
    glEnable(GL_DEPTH_TEST);
    solidProgram.use();
    mesh.drawEdges();
    checkGl("drawing the anti-aliased wireframe");
    multisampled.resolveInto(kColorAttachment, resolved, 0);
    resolved.read(0, GL_RGBA, readback);
    placeTile(readback, 4, tile, wireframe, copyComponents<4>);
  }
  glEnable(GL_DEPTH_TEST);
  glDepthMask(GL_TRUE);
  glDisable(GL_MULTISAMPLE);
}

// The passes drawn with one sample per pixel into `frame`: mask, depth, normal, and the colour
// unless it is anti-aliased (its readback stays in colorReadback for the overlays). The surface
// program's uniforms for the tile are set.
void Rasterizer::Impl::drawSingleSample(const Tile& tile, const PassSelection& passes,
                                        bool offsetSurface, bool colorBuffer, bool antialiased,
                                        Image& color, Image& mask, Image& depth, Image& normal) {
  const float zero[4] = {0, 0, 0, 0};
  frame.bind(tile.width, tile.height);
  frame.setDrawBuffers({colorBuffer, passes.depth, passes.normal});
  if (colorBuffer) frame.clearColor(kColorAttachment, kBackgroundColor);
  if (passes.depth) frame.clearColor(kDepthAttachment, zero);
  if (passes.normal) frame.clearColor(kNormalAttachment, zero);
  frame.clearDepth(0.0f);

  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_GREATER);
  glDepthMask(GL_TRUE);
  surfaceProgram.use();
  drawSurface(offsetSurface);
  checkGl("drawing the surface");

  if (colorBuffer) {
    frame.read(kColorAttachment, GL_RGBA, colorReadback);
    if (passes.color && !antialiased) placeTile(colorReadback, 4, tile, color, copyComponents<4>);
    if (passes.mask) {
      placeTile(colorReadback, 4, tile, mask,
                [](const float* from, float* to) { *to = from[3] > 0.5f ? 1.0f : 0.0f; });
    }
  }
  if (passes.depth) {
    frame.read(kDepthAttachment, GL_RED, readback);
    placeTile(readback, 1, tile, depth, copyComponents<1>);
  }
  if (passes.normal) {
    frame.read(kNormalAttachment, GL_RGBA, readback);
    placeTile(readback, 4, tile, normal, copyComponents<3>);
  }
}

void Rasterizer::Impl::setLineUniforms(const Camera& camera) {
  const bool perspective = camera.projection() == Projection::Perspective;
  const Vec3f eye(camera.eye()), forward(camera.forward());
  // Perspective: the world size of a pixel is depth / pixelsPerUnit(1), and a point moved by
  // that fraction of its distance to the eye moves at least that far along its ray.
  const double bias = perspective ? kOverlayBiasPx / camera.pixelsPerUnit(1.0)
                                  : kOverlayBiasPx / camera.pixelsPerUnit(0.0);
  lineProgram.setVec3("uEye", eye.x, eye.y, eye.z);
  lineProgram.setVec3("uForward", forward.x, forward.y, forward.z);
  lineProgram.setBool("uPerspective", perspective);
  lineProgram.setFloat("uBias", static_cast<float>(bias));
  lineProgram.setFloat("uHalfWidth", kOverlayHalfWidthPx);
}

void Rasterizer::Impl::renderFrame(const Camera& camera, const PassSelection& passes,
                                   Shading shading, const std::vector<LineOverlay>& overlays,
                                   const CancelToken& cancel, ImageSet& out) {
  const int width = camera.width(), height = camera.height();
  const bool antialiased =
      passes.antialias > 1 && (passes.color || passes.wireframe || !overlays.empty());
  // One sample per pixel: the mask, and the colour-like passes unless anti-aliased.
  const bool colorBuffer =
      passes.mask || (!antialiased && (passes.color || passes.wireframe || !overlays.empty()));
  const bool singleSample = colorBuffer || passes.depth || passes.normal;
  Image color, mask, depth, normal, wireframe;
  if (passes.color) color = Image(width, height, 4);
  if (passes.mask) mask = Image(width, height, 1);
  if (passes.depth) depth = Image(width, height, 1);
  if (passes.normal) normal = Image(width, height, 3);
  if (passes.wireframe) wireframe = Image(width, height, 4);
  std::vector<Image> overlayImages(overlays.size());
  for (Image& image : overlayImages) image = Image(width, height, 4);
  const bool offsetSurface =
      passes.wireframe || std::any_of(overlays.begin(), overlays.end(),
                                      [](const LineOverlay& o) { return o.occluded; });
  if (!overlays.empty()) setLineUniforms(camera);

  const Mat4 viewProjection = multiply(camera.projectionMatrix(), camera.viewMatrix());
  const Vec3f eye(camera.eye()), forward(camera.forward());
  surfaceProgram.setVec3("uEye", eye.x, eye.y, eye.z);
  surfaceProgram.setVec3("uForward", forward.x, forward.y, forward.z);
  surfaceProgram.setBool("uPerspective", camera.projection() == Projection::Perspective);
  surfaceProgram.setBool("uSmooth", shading == Shading::Smooth);
  surfaceProgram.setBool("uNormalMap", shading == Shading::NormalMap);
  constexpr GLuint kNormalTextureUnit = 0;
  surfaceProgram.setInt("uNormalTexture", kNormalTextureUnit);
  if (shading == Shading::NormalMap) normalTexture.bind(kNormalTextureUnit);
  const int tileSize =
      antialiased
          ? std::min(frameTileSize,
                     static_cast<int>(std::sqrt(kMultisampleTileSamples / passes.antialias)))
          : frameTileSize;

  for (const Tile& tile : makeTiles(width, height, tileSize)) {
    cancel.check();
    const Mat4 tileViewProjection =
        multiply(tileClipTransform(width, height, tile), viewProjection);
    surfaceProgram.use();
    surfaceProgram.setMatrix("uViewProjection", tileViewProjection);
    if (singleSample)
      drawSingleSample(tile, passes, offsetSurface, colorBuffer, antialiased, color, mask, depth,
                       normal);

    if (!overlays.empty()) {
      lineProgram.use();
      lineProgram.setMatrix("uViewProjection", tileViewProjection);
      lineProgram.setVec2("uViewport", static_cast<float>(tile.width),
                          static_cast<float>(tile.height));
    }
    if (passes.wireframe) {
      solidProgram.use();
      solidProgram.setMatrix("uViewProjection", tileViewProjection);
      solidProgram.setVec4("uColor", kWireColor);
    }
    if (antialiased) {
      drawAntialiased(tile, passes, offsetSurface, overlays, color, wireframe, overlayImages);
      continue;
    }

    // Lines and edges are tested against the surface's depth without changing it.
    glDepthMask(GL_FALSE);
    glDepthFunc(GL_GEQUAL);
    for (size_t k = 0; k < overlays.size(); ++k) {
      drawLines(overlays[k], k, frame);
      frame.readBytes(kOverlayAttachment, GL_RGBA, readbackBytes);
      placeOverlayTile(colorReadback, readbackBytes, tile, overlayImages[k]);
    }
    if (passes.wireframe) {
      frame.setDrawBuffers({true});
      glEnable(GL_DEPTH_TEST);
      solidProgram.use();
      mesh.drawEdges();
      checkGl("drawing the wireframe");
      frame.read(kColorAttachment, GL_RGBA, readback);
      placeTile(readback, 4, tile, wireframe, copyComponents<4>);
    }
    glEnable(GL_DEPTH_TEST);
    glDepthMask(GL_TRUE);
  }
  if (passes.color) out.passes[pass::kColor] = std::move(color);
  if (passes.mask) out.passes[pass::kMask] = std::move(mask);
  if (passes.depth) out.passes[pass::kDepth] = std::move(depth);
  if (passes.normal) out.passes[pass::kNormal] = std::move(normal);
  if (passes.wireframe) out.passes[pass::kWireframe] = std::move(wireframe);
  for (size_t k = 0; k < overlays.size(); ++k) {
    out.passes[overlays[k].pass] = std::move(overlayImages[k]);
  }
}

void Rasterizer::Impl::renderCoverage(const Camera& camera, int supersample,
                                      const CancelToken& cancel, ImageSet& out) {
  const Camera big = camera.scaled(supersample);
  const int width = big.width(), height = big.height();
  // 64 MiB at 8192^2, on huge pages (huge_pages.h): its zero fill, which the tiles then
  // overwrite, takes ~10 ms.
  Mask covered = maskOnHugePages(width, height);
  const Mat4 viewProjection = multiply(big.projectionMatrix(), big.viewMatrix());
  const float one[4] = {1, 1, 1, 1};
  const float zero[4] = {0, 0, 0, 0};

  glDisable(GL_DEPTH_TEST);  // any fragment at all means covered
  if (backFacesHidden) {     // front faces cover all that back faces would
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
  }
  solidProgram.use();
  solidProgram.setVec4("uColor", one);
  for (const Tile& tile : makeTiles(width, height, coverageTileSize)) {
    cancel.check();
    coverage.bind(tile.width, tile.height);
    coverage.setDrawBuffers({true});
    coverage.clearColor(0, zero);
    solidProgram.setMatrix("uViewProjection",
                           multiply(tileClipTransform(width, height, tile), viewProjection));
    mesh.drawTriangles();
    checkGl("drawing the supersampled coverage");
    coverage.readRedBytes(0, readbackBytes);
    placeCoverageTile(readbackBytes, tile, covered);
  }
  glDisable(GL_CULL_FACE);
  out.supersampledMask = std::move(covered);
  out.supersample = supersample;
}

Rasterizer::Rasterizer() : impl_(std::make_unique<Impl>()) {}

Rasterizer::~Rasterizer() = default;

const DeviceInfo& Rasterizer::device() const { return impl_->device; }

void Rasterizer::makeCurrent() { impl_->context.makeCurrent(); }

int Rasterizer::samplesTaken(int samples) const {
  return std::clamp(samples, 1, std::max(impl_->device.maxSamples, 1));
}

std::vector<std::array<float, 2>> Rasterizer::samplePositions(int samples) {
  impl_->context.makeCurrent();
  samples = samplesTaken(samples);
  if (samples == 1) return {{0.5f, 0.5f}};
  Framebuffer probe({GL_RGBA8}, /*withDepth=*/false);
  probe.bind(1, 1, samples);
  return probe.samplePositions();
}

ImageSet Rasterizer::render(const tessellate::TriangleMesh& mesh, const Camera& camera,
                            const PassSelection& passes, Shading shading,
                            const std::vector<LineOverlay>& overlays, const CancelToken& cancel) {
  if (camera.width() <= 0 || camera.height() <= 0) {
    throw std::invalid_argument("raster: the camera's image size must be positive");
  }
  if (passes.supersample < 0) {
    throw std::invalid_argument("raster: the supersample factor must not be negative");
  }
  if (passes.antialias < 1) {
    throw std::invalid_argument("raster: antialias must be at least 1 sample, got " +
                                std::to_string(passes.antialias));
  }
  validateOverlays(overlays);
  const bool mapped = shading == Shading::NormalMap;
  if (mapped && (!mesh.normalMap || mesh.texcoords.size() != mesh.positions.size())) {
    throw std::invalid_argument(
        "raster: normal-map shading needs a normal map and one texture coordinate per vertex");
  }
  impl_->context.makeCurrent();
  ImageSet result;
  const bool frame = passes.color || passes.mask || passes.depth || passes.normal ||
                     passes.wireframe || !overlays.empty();
  if (!frame && passes.supersample == 0) return result;

  impl_->mesh.upload(mesh, mapped);
  impl_->backFacesHidden = mesh.closedOutward && inFrontOfNearPlane(mesh, camera);
  if (mapped && frame) impl_->normalTexture.upload(*mesh.normalMap);
  if (!overlays.empty()) impl_->overlayLines.upload(overlays);
  PassSelection drawn = passes;
  drawn.antialias = std::min(passes.antialias, samplesTaken(passes.antialias));
  if (frame) impl_->renderFrame(camera, drawn, shading, overlays, cancel, result);
  if (passes.supersample > 0) impl_->renderCoverage(camera, passes.supersample, cancel, result);
  return result;
}

}  // namespace limn::render::raster
