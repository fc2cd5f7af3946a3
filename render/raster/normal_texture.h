// NormalTexture: a normal map (render/core Image, 3 float channels) as an OpenGL texture for the
// surface program's NormalMap shading: GL_RGB32F, bilinear (GL_LINEAR, no mipmaps), clamped to
// the edge. Created once per Rasterizer and refilled by every render that uses a normal map;
// the storage is kept while the size stays the same.
#pragma once

#include "render/core/image.h"
#include "render/raster/gl_api.h"

namespace limn::render::raster {

class NormalTexture {
 public:
  NormalTexture();
  ~NormalTexture();
  NormalTexture(const NormalTexture&) = delete;
  NormalTexture& operator=(const NormalTexture&) = delete;

  // Uploads `map` with row 0 at texture coordinate t = 0. Throws std::invalid_argument when it
  // is empty, has other than 3 channels, or is larger than GL_MAX_TEXTURE_SIZE (maxSide()).
  void upload(const Image& map);
  void bind(GLuint unit) const;

  int maxSide() const { return maxSide_; }

 private:
  GLuint texture_ = 0;
  int width_ = 0, height_ = 0;
  int maxSide_ = 0;
};

}  // namespace limn::render::raster
