#include "render/raster/gl_error.h"

#include <cstdio>
#include <stdexcept>

namespace limn::render::raster {

std::string glErrorName(GLenum error) {
  switch (error) {
    case GL_INVALID_ENUM:
      return "GL_INVALID_ENUM";
    case GL_INVALID_VALUE:
      return "GL_INVALID_VALUE";
    case GL_INVALID_OPERATION:
      return "GL_INVALID_OPERATION";
    case GL_INVALID_FRAMEBUFFER_OPERATION:
      return "GL_INVALID_FRAMEBUFFER_OPERATION";
    case GL_OUT_OF_MEMORY:
      return "GL_OUT_OF_MEMORY";
    case GL_STACK_OVERFLOW:
      return "GL_STACK_OVERFLOW";
    case GL_STACK_UNDERFLOW:
      return "GL_STACK_UNDERFLOW";
    default: {
      char buf[32];
      std::snprintf(buf, sizeof buf, "GL error 0x%04X", error);
      return buf;
    }
  }
}

void checkGl(const char* what) {
  std::string errors;
  // Several flags may be pending; glGetError returns and clears them one at a time.
  for (int i = 0; i < 16; ++i) {
    GLenum error = glGetError();
    if (error == GL_NO_ERROR) break;
    if (!errors.empty()) errors += ", ";
    errors += glErrorName(error);
  }
  if (!errors.empty()) {
    throw std::runtime_error("OpenGL error " + errors + " while " + what);
  }
}

void checkFramebuffer(GLuint framebuffer, const char* what) {
  GLenum status = glCheckNamedFramebufferStatus(framebuffer, GL_FRAMEBUFFER);
  if (status == GL_FRAMEBUFFER_COMPLETE) return;
  const char* name = "unknown status";
  switch (status) {
    case GL_FRAMEBUFFER_UNDEFINED:
      name = "GL_FRAMEBUFFER_UNDEFINED";
      break;
    case GL_FRAMEBUFFER_INCOMPLETE_ATTACHMENT:
      name = "GL_FRAMEBUFFER_INCOMPLETE_ATTACHMENT";
      break;
    case GL_FRAMEBUFFER_INCOMPLETE_MISSING_ATTACHMENT:
      name = "GL_FRAMEBUFFER_INCOMPLETE_MISSING_ATTACHMENT";
      break;
    case GL_FRAMEBUFFER_UNSUPPORTED:
      name = "GL_FRAMEBUFFER_UNSUPPORTED";
      break;
    case GL_FRAMEBUFFER_INCOMPLETE_MULTISAMPLE:
      name = "GL_FRAMEBUFFER_INCOMPLETE_MULTISAMPLE";
      break;
    default:
      break;
  }
  throw std::runtime_error(std::string("framebuffer incomplete (") + name + ") while " + what);
}

}  // namespace limn::render::raster
