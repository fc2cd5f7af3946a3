// Turning OpenGL's error flags and framebuffer status into exceptions with a clear message,
// so a failed allocation or an unsupported format surfaces as std::runtime_error naming the step.
#pragma once

#include <string>

#include "render/raster/gl_api.h"

namespace limn::render::raster {

// Throws std::runtime_error("OpenGL error GL_... while <what>") if any GL error flag is set;
// clears all pending flags either way.
void checkGl(const char* what);

// Throws std::runtime_error when `framebuffer` is not complete.
void checkFramebuffer(GLuint framebuffer, const char* what);

std::string glErrorName(GLenum error);

}  // namespace limn::render::raster
