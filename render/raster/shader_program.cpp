#include "render/raster/shader_program.h"

#include <algorithm>
#include <stdexcept>
#include <vector>

namespace limn::render::raster {

namespace {

std::string shaderLog(GLuint shader) {
  GLint length = 0;
  glGetShaderiv(shader, GL_INFO_LOG_LENGTH, &length);
  std::vector<char> log(static_cast<size_t>(std::max(length, 1)), '\0');
  glGetShaderInfoLog(shader, length, nullptr, log.data());
  return log.data();
}

std::string programLog(GLuint program) {
  GLint length = 0;
  glGetProgramiv(program, GL_INFO_LOG_LENGTH, &length);
  std::vector<char> log(static_cast<size_t>(std::max(length, 1)), '\0');
  glGetProgramInfoLog(program, length, nullptr, log.data());
  return log.data();
}

GLuint compile(GLenum stage, const std::string& source, const std::string& what) {
  GLuint shader = glCreateShader(stage);
  const char* text = source.c_str();
  glShaderSource(shader, 1, &text, nullptr);
  glCompileShader(shader);
  GLint ok = GL_FALSE;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    std::string log = shaderLog(shader);
    glDeleteShader(shader);
    throw std::runtime_error("cannot compile the " + what + ": " + log);
  }
  return shader;
}

}  // namespace

ShaderProgram::ShaderProgram(const std::string& name, const std::string& vertexSource,
                             const std::string& fragmentSource) {
  GLuint vertex = compile(GL_VERTEX_SHADER, vertexSource, name + " vertex shader");
  GLuint fragment = 0;
  try {
    fragment = compile(GL_FRAGMENT_SHADER, fragmentSource, name + " fragment shader");
  } catch (...) {
    glDeleteShader(vertex);
    throw;
  }
  program_ = glCreateProgram();
  glAttachShader(program_, vertex);
  glAttachShader(program_, fragment);
  glLinkProgram(program_);
  // The program keeps what it needs; the shader objects can go now.
  glDeleteShader(vertex);
  glDeleteShader(fragment);
  GLint ok = GL_FALSE;
  glGetProgramiv(program_, GL_LINK_STATUS, &ok);
  if (!ok) {
    std::string log = programLog(program_);
    glDeleteProgram(program_);
    throw std::runtime_error("cannot link the " + name + " program: " + log);
  }
}

ShaderProgram::~ShaderProgram() { glDeleteProgram(program_); }

void ShaderProgram::setMatrix(const char* uniform, const std::array<float, 16>& m) const {
  glProgramUniformMatrix4fv(program_, location(uniform), 1, GL_FALSE, m.data());
}

void ShaderProgram::setVec3(const char* uniform, float x, float y, float z) const {
  glProgramUniform3f(program_, location(uniform), x, y, z);
}

void ShaderProgram::setVec4(const char* uniform, const float rgba[4]) const {
  glProgramUniform4fv(program_, location(uniform), 1, rgba);
}

void ShaderProgram::setBool(const char* uniform, bool value) const {
  glProgramUniform1i(program_, location(uniform), value ? 1 : 0);
}

}  // namespace limn::render::raster
