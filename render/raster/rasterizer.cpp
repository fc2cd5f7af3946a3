#include "render/raster/rasterizer.h"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

#include "render/core/shading.h"
#include "render/raster/egl_context.h"
#include "render/raster/framebuffer.h"
#include "render/raster/gl_api.h"
#include "render/raster/gl_error.h"
#include "render/raster/mesh_buffers.h"
#include "render/raster/shader_program.h"
#include "render/raster/shaders.h"
#include "render/raster/tiling.h"

namespace limn::render::raster {

namespace {

// Largest tile of each framebuffer, besides the GL limits: the frame pass holds 40 bytes per
// pixel (2048^2: 160 MiB), the coverage pass 1 byte per pixel (4096^2: 16 MiB).
constexpr int kFrameTileCap = 2048;
constexpr int kCoverageTileCap = 4096;

// Attachments of the frame pass; fragment output i writes attachment i.
enum FrameAttachment { kColorAttachment = 0, kDepthAttachment = 1, kNormalAttachment = 2 };

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
// into its place in `dst` (top row first), through `convert(const T* src, float* dst)`.
template <typename T, typename Convert>
void placeTile(const std::vector<T>& src, int srcComponents, const Tile& tile, Image& dst,
               Convert convert) {
  for (int r = 0; r < tile.height; ++r) {
    const int dstRow = tile.y + tile.height - 1 - r;
    for (int i = 0; i < tile.width; ++i) {
      const T* from = &src[(static_cast<size_t>(r) * tile.width + i) * srcComponents];
      convert(from, &dst.at(tile.x + i, dstRow, 0));
    }
  }
}

template <int N>
void copyComponents(const float* from, float* to) {
  std::copy(from, from + N, to);
}

}  // namespace

struct Rasterizer::Impl {
  EglContext context;  // first: everything below needs it current
  DeviceInfo device;
  ShaderProgram surfaceProgram{"surface", surfaceVertexShader(), surfaceFragmentShader()};
  ShaderProgram solidProgram{"solid", solidVertexShader(), solidFragmentShader()};
  MeshBuffers mesh;
  Framebuffer frame{{GL_RGBA32F, GL_R32F, GL_RGBA32F}, /*withDepth=*/true};
  Framebuffer coverage{{GL_R8}, /*withDepth=*/false};
  int frameTileSize = 0;
  int coverageTileSize = 0;
  std::vector<float> readback;
  std::vector<unsigned char> readbackBytes;

  Impl();
  ~Impl();
  void renderFrame(const Camera& camera, const PassSelection& passes, Shading shading,
                   ImageSet& out);
  void renderCoverage(const Camera& camera, int supersample, ImageSet& out);
};

Rasterizer::Impl::Impl() {
  device.renderer = glString(GL_RENDERER);
  device.vendor = glString(GL_VENDOR);
  device.version = glString(GL_VERSION);
  device.eglPlatform = context.platform();

  const int largest = largestFramebufferSide();
  frameTileSize = std::min(largest, kFrameTileCap);
  coverageTileSize = std::min(largest, kCoverageTileCap);

  // Fixed state for all passes: reversed float depth (see tiling.h), no dithering, no
  // multisampling, no culling (back faces are drawn and shaded with the back albedo).
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

void Rasterizer::Impl::renderFrame(const Camera& camera, const PassSelection& passes,
                                   Shading shading, ImageSet& out) {
  const int width = camera.width(), height = camera.height();
  const bool colorBuffer = passes.color || passes.mask || passes.wireframe;
  Image color, mask, depth, normal, wireframe;
  if (passes.color) color = Image(width, height, 4);
  if (passes.mask) mask = Image(width, height, 1);
  if (passes.depth) depth = Image(width, height, 1);
  if (passes.normal) normal = Image(width, height, 3);
  if (passes.wireframe) wireframe = Image(width, height, 4);

  const Mat4 viewProjection = multiply(camera.projectionMatrix(), camera.viewMatrix());
  const Vec3f eye(camera.eye()), forward(camera.forward());
  surfaceProgram.setVec3("uEye", eye.x, eye.y, eye.z);
  surfaceProgram.setVec3("uForward", forward.x, forward.y, forward.z);
  surfaceProgram.setBool("uPerspective", camera.projection() == Projection::Perspective);
  surfaceProgram.setBool("uSmooth", shading == Shading::Smooth);
  const float wireColor[4] = {shading::kWireColor[0], shading::kWireColor[1],
                              shading::kWireColor[2], 1.0f};
  const float background[4] = {shading::kBackground[0], shading::kBackground[1],
                               shading::kBackground[2], 0.0f};
  const float zero[4] = {0, 0, 0, 0};

  for (const Tile& tile : makeTiles(width, height, frameTileSize)) {
    const Mat4 tileViewProjection =
        multiply(tileClipTransform(width, height, tile), viewProjection);
    frame.bind(tile.width, tile.height);
    frame.setDrawBuffers({colorBuffer, passes.depth, passes.normal});
    if (colorBuffer) frame.clearColor(kColorAttachment, background);
    if (passes.depth) frame.clearColor(kDepthAttachment, zero);
    if (passes.normal) frame.clearColor(kNormalAttachment, zero);
    frame.clearDepth(0.0f);

    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_GREATER);
    glDepthMask(GL_TRUE);
    if (passes.wireframe) {
      // Push the surface back a little so edges lying on it pass the depth test, while edges
      // behind other surfaces still fail it.
      glEnable(GL_POLYGON_OFFSET_FILL);
      glPolygonOffset(-1.0f, -1.0f);
    }
    surfaceProgram.use();
    surfaceProgram.setMatrix("uViewProjection", tileViewProjection);
    mesh.drawTriangles();
    glDisable(GL_POLYGON_OFFSET_FILL);
    checkGl("drawing the surface");

    if (colorBuffer) {
      frame.read(kColorAttachment, GL_RGBA, readback);
      if (passes.color) placeTile(readback, 4, tile, color, copyComponents<4>);
      if (passes.mask) {
        placeTile(readback, 4, tile, mask,
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

    if (passes.wireframe) {
      frame.setDrawBuffers({true});
      glDepthFunc(GL_GEQUAL);
      glDepthMask(GL_FALSE);
      solidProgram.use();
      solidProgram.setMatrix("uViewProjection", tileViewProjection);
      solidProgram.setVec4("uColor", wireColor);
      mesh.drawEdges();
      glDepthMask(GL_TRUE);
      checkGl("drawing the wireframe");
      frame.read(kColorAttachment, GL_RGBA, readback);
      placeTile(readback, 4, tile, wireframe, copyComponents<4>);
    }
  }
  if (passes.color) out.passes[pass::kColor] = std::move(color);
  if (passes.mask) out.passes[pass::kMask] = std::move(mask);
  if (passes.depth) out.passes[pass::kDepth] = std::move(depth);
  if (passes.normal) out.passes[pass::kNormal] = std::move(normal);
  if (passes.wireframe) out.passes[pass::kWireframe] = std::move(wireframe);
}

void Rasterizer::Impl::renderCoverage(const Camera& camera, int supersample, ImageSet& out) {
  const Camera big = camera.scaled(supersample);
  const int width = big.width(), height = big.height();
  Image covered(width, height, 1);
  const Mat4 viewProjection = multiply(big.projectionMatrix(), big.viewMatrix());
  const float one[4] = {1, 1, 1, 1};
  const float zero[4] = {0, 0, 0, 0};

  glDisable(GL_DEPTH_TEST);  // any fragment at all means covered
  solidProgram.use();
  solidProgram.setVec4("uColor", one);
  for (const Tile& tile : makeTiles(width, height, coverageTileSize)) {
    coverage.bind(tile.width, tile.height);
    coverage.setDrawBuffers({true});
    coverage.clearColor(0, zero);
    solidProgram.setMatrix("uViewProjection",
                           multiply(tileClipTransform(width, height, tile), viewProjection));
    mesh.drawTriangles();
    checkGl("drawing the supersampled coverage");
    coverage.readRedBytes(0, readbackBytes);
    placeTile(readbackBytes, 1, tile, covered,
              [](const unsigned char* from, float* to) { *to = *from > 127 ? 1.0f : 0.0f; });
  }
  out.supersampledMask = std::move(covered);
  out.supersample = supersample;
}

Rasterizer::Rasterizer() : impl_(std::make_unique<Impl>()) {}

Rasterizer::~Rasterizer() = default;

const DeviceInfo& Rasterizer::device() const { return impl_->device; }

ImageSet Rasterizer::render(const tessellate::TriangleMesh& mesh, const Camera& camera,
                            const PassSelection& passes, Shading shading) {
  if (camera.width() <= 0 || camera.height() <= 0) {
    throw std::invalid_argument("raster: the camera's image size must be positive");
  }
  if (passes.supersample < 0) {
    throw std::invalid_argument("raster: the supersample factor must not be negative");
  }
  impl_->context.makeCurrent();
  ImageSet result;
  const bool frame =
      passes.color || passes.mask || passes.depth || passes.normal || passes.wireframe;
  if (!frame && passes.supersample == 0) return result;

  impl_->mesh.upload(mesh);
  if (frame) impl_->renderFrame(camera, passes, shading, result);
  if (passes.supersample > 0) impl_->renderCoverage(camera, passes.supersample, result);
  return result;
}

}  // namespace limn::render::raster
