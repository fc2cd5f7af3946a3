// ShaderProgram: a linked GLSL program owned by one context: vertex, optional geometry and
// fragment stages, or any list of stages (tessellation, transform feedback without a fragment
// stage).
// Compile and link errors become std::runtime_error with the driver's log. Uniforms are set through
// the direct-state-access calls, so the program need not be bound to be configured.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "render/raster/gl_api.h"

namespace limn::render::raster {

struct ShaderStage {
  GLenum type;  // GL_VERTEX_SHADER, GL_TESS_CONTROL_SHADER, ...
  std::string source;
};

class ShaderProgram {
 public:
  // An empty geometrySource means no geometry stage.
  ShaderProgram(const std::string& name, const std::string& vertexSource,
                const std::string& fragmentSource, const std::string& geometrySource = "");
  // `feedbackVaryings`: outputs of the last vertex-processing stage captured by transform
  // feedback, interleaved in this order into one buffer.
  ShaderProgram(const std::string& name, const std::vector<ShaderStage>& stages,
                const std::vector<std::string>& feedbackVaryings = {});
  ~ShaderProgram();
  ShaderProgram(const ShaderProgram&) = delete;
  ShaderProgram& operator=(const ShaderProgram&) = delete;

  void use() const { glUseProgram(program_); }

  // Setting a uniform the compiler optimised away is not an error (location -1 is ignored).
  void setMatrix(const char* uniform, const std::array<float, 16>& columnMajor) const;
  void setVec3(const char* uniform, float x, float y, float z) const;
  void setVec4(const char* uniform, const float rgba[4]) const;
  void setBool(const char* uniform, bool value) const;
  void setInt(const char* uniform, int value) const;
  void setFloat(const char* uniform, float value) const;
  void setVec2(const char* uniform, float x, float y) const;

 private:
  GLint location(const char* uniform) const { return glGetUniformLocation(program_, uniform); }

  GLuint program_ = 0;
};

}  // namespace limn::render::raster
