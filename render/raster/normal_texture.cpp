#include "render/raster/normal_texture.h"

#include <stdexcept>
#include <string>

#include "render/raster/gl_error.h"

namespace limn::render::raster {

NormalTexture::NormalTexture() {
  GLint largest = 0;
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &largest);
  maxSide_ = largest;
  checkGl("querying the largest texture");
}

NormalTexture::~NormalTexture() {
  if (texture_) glDeleteTextures(1, &texture_);
}

void NormalTexture::upload(const Image& map) {
  if (map.empty() || map.channels != 3) {
    throw std::invalid_argument("raster: a normal map must be a non-empty image of 3 channels");
  }
  if (map.width > maxSide_ || map.height > maxSide_) {
    throw std::invalid_argument("raster: the normal map (" + std::to_string(map.width) + " x " +
                                std::to_string(map.height) + ") is larger than this device's " +
                                "largest texture (" + std::to_string(maxSide_) + ")");
  }
  if (map.width != width_ || map.height != height_) {
    // Immutable storage: a new size needs a new texture object.
    if (texture_) glDeleteTextures(1, &texture_);
    width_ = height_ = 0;
    glCreateTextures(GL_TEXTURE_2D, 1, &texture_);
    glTextureStorage2D(texture_, 1, GL_RGB32F, map.width, map.height);
    glTextureParameteri(texture_, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTextureParameteri(texture_, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTextureParameteri(texture_, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTextureParameteri(texture_, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    checkGl("allocating the normal map texture (out of GPU memory?)");
    width_ = map.width;
    height_ = map.height;
  }
  // Rows of 3 floats are always 4-byte aligned. GL's first row is at t = 0, as in limn's
  // texture coordinate convention (triangle_mesh.h).
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
  glTextureSubImage2D(texture_, 0, 0, 0, map.width, map.height, GL_RGB, GL_FLOAT,
                      map.pixels.data());
  checkGl("uploading the normal map");
}

void NormalTexture::bind(GLuint unit) const { glBindTextureUnit(unit, texture_); }

}  // namespace limn::render::raster
