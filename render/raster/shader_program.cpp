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

const char* stageName(GLenum type) {
  switch (type) {
    case GL_VERTEX_SHADER:
      return " vertex shader";
    case GL_TESS_CONTROL_SHADER:
      return " tessellation control shader";
    case GL_TESS_EVALUATION_SHADER:
      return " tessellation evaluation shader";
    case GL_GEOMETRY_SHADER:
      return " geometry shader";
    case GL_FRAGMENT_SHADER:
      return " fragment shader";
    default:
      return " shader";
  }
}

std::vector<ShaderStage> classicStages(const std::string& vertexSource,
                                       const std::string& fragmentSource,
                                       const std::string& geometrySource) {
  std::vector<ShaderStage> stages = {{GL_VERTEX_SHADER, vertexSource},
                                     {GL_FRAGMENT_SHADER, fragmentSource}};
  if (!geometrySource.empty()) stages.push_back({GL_GEOMETRY_SHADER, geometrySource});
  return stages;
}

}  // namespace

ShaderProgram::ShaderProgram(const std::string& name, const std::string& vertexSource,
                             const std::string& fragmentSource, const std::string& geometrySource)
    : ShaderProgram(name, classicStages(vertexSource, fragmentSource, geometrySource)) {}

ShaderProgram::ShaderProgram(const std::string& name, const std::vector<ShaderStage>& stages,
                             const std::vector<std::string>& feedbackVaryings) {
  std::vector<GLuint> shaders;
  try {
    for (const ShaderStage& stage : stages) {
      shaders.push_back(compile(stage.type, stage.source, name + stageName(stage.type)));
    }
  } catch (...) {
    for (GLuint shader : shaders) glDeleteShader(shader);
    throw;
  }
  program_ = glCreateProgram();
  for (GLuint shader : shaders) glAttachShader(program_, shader);
  if (!feedbackVaryings.empty()) {
    std::vector<const char*> names;
    for (const std::string& v : feedbackVaryings) names.push_back(v.c_str());
    glTransformFeedbackVaryings(program_, static_cast<GLsizei>(names.size()), names.data(),
                                GL_INTERLEAVED_ATTRIBS);
  }
  glLinkProgram(program_);
  // The program keeps what it needs; the shader objects can go now.
  for (GLuint shader : shaders) glDeleteShader(shader);
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

void ShaderProgram::setInt(const char* uniform, int value) const {
  glProgramUniform1i(program_, location(uniform), value);
}

void ShaderProgram::setFloat(const char* uniform, float value) const {
  glProgramUniform1f(program_, location(uniform), value);
}

void ShaderProgram::setVec2(const char* uniform, float x, float y) const {
  glProgramUniform2f(program_, location(uniform), x, y);
}

}  // namespace limn::render::raster
