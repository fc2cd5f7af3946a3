// Framebuffer: an offscreen framebuffer object with a fixed list of colour attachments (one
// renderbuffer each, in the given internal formats; GL_NONE leaves that attachment empty) and
// optionally a float depth buffer, single-sampled or multisampled. Storage is (re)allocated
// only when the requested size or sample count changes, so a Rasterizer that renders the same
// size again reuses it.
#pragma once

#include <array>
#include <vector>

#include "render/raster/gl_api.h"

namespace limn::render::raster {

class Framebuffer {
 public:
  Framebuffer(std::vector<GLenum> colorFormats, bool withDepth);
  ~Framebuffer();
  Framebuffer(const Framebuffer&) = delete;
  Framebuffer& operator=(const Framebuffer&) = delete;

  // Makes the attachments width x height with `samples` samples per pixel (0: single-sampled;
  // no-op when they already are) and binds the framebuffer for drawing with a matching viewport.
  void bind(int width, int height, int samples = 0);

  // Chooses which attachments the fragment outputs 0..n-1 write to; false means "none".
  void setDrawBuffers(const std::vector<bool>& enabled);
  void clearColor(int attachment, const float value[4]);
  void clearDepth(float value);

  // Reads attachment `attachment` as floats, `components` per pixel (GL_RED: 1, GL_RGBA: 4),
  // bottom row first as OpenGL stores it.
  void read(int attachment, GLenum format, std::vector<float>& out) const;
  // Reads the red channel of an 8-bit attachment as bytes (4 times less to convert and copy
  // than floats, which matters for the large supersampled coverage).
  void readRedBytes(int attachment, std::vector<unsigned char>& out) const {
    readBytes(attachment, GL_RED, out);
  }
  // Reads an 8-bit attachment as bytes, GL_RED (1 per pixel) or GL_RGBA (4 per pixel).
  void readBytes(int attachment, GLenum format, std::vector<unsigned char>& out) const;

  // Resolves (multisampled: averages each pixel's samples) or copies attachment `attachment`
  // into attachment `targetAttachment` of `target`, which has the same size and format.
  void resolveInto(int attachment, Framebuffer& target, int targetAttachment) const;

  // The sample positions of the bound multisampled framebuffer, within the pixel: x right and y
  // down (limn's convention, camera.h), in [0, 1].
  std::vector<std::array<float, 2>> samplePositions() const;

  int width() const { return width_; }
  int height() const { return height_; }

 private:
  void allocate(int width, int height, int samples);

  std::vector<GLenum> colorFormats_;
  bool withDepth_;
  GLuint framebuffer_ = 0;
  std::vector<GLuint> colorBuffers_;
  GLuint depthBuffer_ = 0;
  int width_ = 0, height_ = 0, samples_ = 0;
};

}  // namespace limn::render::raster
