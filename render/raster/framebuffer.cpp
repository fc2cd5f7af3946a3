#include "render/raster/framebuffer.h"

#include <stdexcept>
#include <string>

#include "render/raster/gl_error.h"

namespace limn::render::raster {

Framebuffer::Framebuffer(std::vector<GLenum> colorFormats, bool withDepth)
    : colorFormats_(std::move(colorFormats)), withDepth_(withDepth) {
  glCreateFramebuffers(1, &framebuffer_);
  checkGl("creating a framebuffer");
}

Framebuffer::~Framebuffer() {
  if (!colorBuffers_.empty()) {
    glDeleteRenderbuffers(static_cast<GLsizei>(colorBuffers_.size()), colorBuffers_.data());
  }
  if (depthBuffer_) glDeleteRenderbuffers(1, &depthBuffer_);
  glDeleteFramebuffers(1, &framebuffer_);
}

void Framebuffer::allocate(int width, int height, int samples) {
  // Fresh renderbuffers: the old ones go first so that both are never held at once.
  if (!colorBuffers_.empty()) {
    glDeleteRenderbuffers(static_cast<GLsizei>(colorBuffers_.size()), colorBuffers_.data());
  }
  if (depthBuffer_) glDeleteRenderbuffers(1, &depthBuffer_);
  width_ = height_ = 0;

  colorBuffers_.assign(colorFormats_.size(), 0);
  glCreateRenderbuffers(static_cast<GLsizei>(colorBuffers_.size()), colorBuffers_.data());
  for (size_t i = 0; i < colorBuffers_.size(); ++i) {
    const GLenum attachment = GL_COLOR_ATTACHMENT0 + static_cast<GLenum>(i);
    if (colorFormats_[i] == GL_NONE) {
      glNamedFramebufferRenderbuffer(framebuffer_, attachment, GL_RENDERBUFFER, 0);
      continue;
    }
    glNamedRenderbufferStorageMultisample(colorBuffers_[i], samples, colorFormats_[i], width,
                                          height);
    glNamedFramebufferRenderbuffer(framebuffer_, attachment, GL_RENDERBUFFER, colorBuffers_[i]);
  }
  depthBuffer_ = 0;
  if (withDepth_) {
    glCreateRenderbuffers(1, &depthBuffer_);
    glNamedRenderbufferStorageMultisample(depthBuffer_, samples, GL_DEPTH_COMPONENT32F, width,
                                          height);
    glNamedFramebufferRenderbuffer(framebuffer_, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER,
                                   depthBuffer_);
  }
  const std::string what = "allocating a " + std::to_string(width) + " x " +
                           std::to_string(height) + " framebuffer of " + std::to_string(samples) +
                           " samples";
  checkGl(what.c_str());
  checkFramebuffer(framebuffer_, what.c_str());
  width_ = width;
  height_ = height;
  samples_ = samples;
}

void Framebuffer::bind(int width, int height, int samples) {
  if (width != width_ || height != height_ || samples != samples_) {
    allocate(width, height, samples);
  }
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer_);
  glViewport(0, 0, width, height);
}

void Framebuffer::setDrawBuffers(const std::vector<bool>& enabled) {
  std::vector<GLenum> buffers;
  for (size_t i = 0; i < enabled.size(); ++i) {
    buffers.push_back(enabled[i] ? GL_COLOR_ATTACHMENT0 + static_cast<GLenum>(i) : GL_NONE);
  }
  glNamedFramebufferDrawBuffers(framebuffer_, static_cast<GLsizei>(buffers.size()), buffers.data());
}

void Framebuffer::clearColor(int attachment, const float value[4]) {
  // Clears go by draw buffer index; attachment i is always draw buffer i here.
  glClearNamedFramebufferfv(framebuffer_, GL_COLOR, attachment, value);
}

void Framebuffer::clearDepth(float value) {
  glClearNamedFramebufferfv(framebuffer_, GL_DEPTH, 0, &value);
}

void Framebuffer::resolveInto(int attachment, Framebuffer& target, int targetAttachment) const {
  glNamedFramebufferReadBuffer(framebuffer_,
                               GL_COLOR_ATTACHMENT0 + static_cast<GLenum>(attachment));
  glNamedFramebufferDrawBuffer(target.framebuffer_,
                               GL_COLOR_ATTACHMENT0 + static_cast<GLenum>(targetAttachment));
  glBlitNamedFramebuffer(framebuffer_, target.framebuffer_, 0, 0, width_, height_, 0, 0,
                         target.width_, target.height_, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  checkGl("resolving a multisampled attachment");
}

std::vector<std::array<float, 2>> Framebuffer::samplePositions() const {
  std::vector<std::array<float, 2>> positions(samples_);
  for (int i = 0; i < samples_; ++i) {
    GLfloat at[2] = {0.5f, 0.5f};
    glGetMultisamplefv(GL_SAMPLE_POSITION, static_cast<GLuint>(i), at);
    positions[i] = {at[0], 1.0f - at[1]};  // OpenGL's y runs up
  }
  checkGl("querying the sample positions");
  return positions;
}

void Framebuffer::read(int attachment, GLenum format, std::vector<float>& out) const {
  const size_t components = format == GL_RGBA ? 4 : 1;
  out.resize(static_cast<size_t>(width_) * height_ * components);
  glNamedFramebufferReadBuffer(framebuffer_,
                               GL_COLOR_ATTACHMENT0 + static_cast<GLenum>(attachment));
  glBindFramebuffer(GL_READ_FRAMEBUFFER, framebuffer_);
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  glReadnPixels(0, 0, width_, height_, format, GL_FLOAT,
                static_cast<GLsizei>(out.size() * sizeof(float)), out.data());
  checkGl("reading back a framebuffer attachment");
}

void Framebuffer::readBytes(int attachment, GLenum format, std::vector<unsigned char>& out) const {
  const size_t components = format == GL_RGBA ? 4 : 1;
  out.resize(static_cast<size_t>(width_) * height_ * components);
  glNamedFramebufferReadBuffer(framebuffer_,
                               GL_COLOR_ATTACHMENT0 + static_cast<GLenum>(attachment));
  glBindFramebuffer(GL_READ_FRAMEBUFFER, framebuffer_);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadnPixels(0, 0, width_, height_, format, GL_UNSIGNED_BYTE, static_cast<GLsizei>(out.size()),
                out.data());
  checkGl("reading back a framebuffer attachment");
}

}  // namespace limn::render::raster
