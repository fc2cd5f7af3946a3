// Encoding of ImageSet passes into files held in memory (PNG 8-bit, JPEG, WebP or OpenEXR
// float), through OpenImageIO, and decoding for tests and tools.
#pragma once

#include <string>
#include <vector>

#include "render/core/image.h"

namespace limn::render::image {

enum class Format { Png, Exr, Jpeg, Webp };

// Quality of the lossy formats (JPEG, WebP), 1..100.
inline constexpr int kDefaultQuality = 90;

// How a request's images are encoded.
struct Encoding {
  Format format = Format::Png;
  int quality = kDefaultQuality;  // JPEG and WebP only
};

struct EncodedImage {
  std::string mime;  // "image/png", "image/x-exr", "image/jpeg", "image/webp" or "image/gif"
  int width = 0, height = 0;
  std::vector<unsigned char> bytes;
};

// How a pass maps to 8 bits for PNG: color/wireframe as RGBA, mask as grey 0/255, depth as
// grey with the nearest covered depth white and the farthest dark (empty pixels black),
// normal as RGB = (n + 1) / 2 (empty pixels black). EXR keeps the float values as they are.
// JPEG and WebP take the same 8-bit values at `quality`; JPEG has no alpha, so an RGBA image is
// laid over white first; WebP keeps RGBA and writes grey images as RGB.
EncodedImage encode(const Image& image, const std::string& passName, Format format,
                    int quality = kDefaultQuality);

// An animated GIF of `frames` (colour passes of one size, RGBA laid over white: GIF has no
// partial alpha), looping, at `fps` frames a second. OpenImageIO 2.4 writes animation as GIF
// only (its WebP writer takes one image).
EncodedImage encodeAnimation(const std::vector<const Image*>& frames, double fps);

// Decodes PNG, EXR, JPEG or WebP bytes into float pixels (8-bit values scaled to [0, 1]).
Image decode(const std::vector<unsigned char>& bytes);

}  // namespace limn::render::image
