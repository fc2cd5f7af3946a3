// Encoding of ImageSet passes into files held in memory (PNG 8-bit or OpenEXR float), through
// OpenImageIO, and decoding for tests and tools.
#pragma once

#include <string>
#include <vector>

#include "render/core/image.h"

namespace limn::render::image {

enum class Format { Png, Exr };

struct EncodedImage {
  std::string mime;  // "image/png" or "image/x-exr"
  int width = 0, height = 0;
  std::vector<unsigned char> bytes;
};

// How a pass maps to 8 bits for PNG: color/wireframe as RGBA, mask as grey 0/255, depth as
// grey with the nearest covered depth white and the farthest dark (empty pixels black),
// normal as RGB = (n + 1) / 2 (empty pixels black). EXR keeps the float values as they are.
EncodedImage encode(const Image& image, const std::string& passName, Format format);

// Decodes PNG or EXR bytes into float pixels (PNG values scaled to [0, 1]).
Image decode(const std::vector<unsigned char>& bytes);

}  // namespace limn::render::image
