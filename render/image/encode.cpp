#include "render/image/encode.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include "render/image/pixel_mapping.h"

namespace limn::render::image {

namespace {

// EXR channel names: depth is the conventional "Z", other single channels are luminance "Y".
std::vector<std::string> exrChannelNames(int channels, const std::string& passName) {
  if (channels == 1) return {passName == pass::kDepth ? "Z" : "Y"};
  static const char* kRgba[4] = {"R", "G", "B", "A"};
  std::vector<std::string> names;
  for (int c = 0; c < channels; ++c) {
    names.push_back(c < 4 ? kRgba[c] : "channel" + std::to_string(c));
  }
  return names;
}

void checkEncodable(const Image& image) {
  if (image.width <= 0 || image.height <= 0 || image.channels <= 0 ||
      image.pixels.size() != static_cast<size_t>(image.width) * image.height * image.channels) {
    throw std::invalid_argument("image::encode: the image is empty or its pixel count is wrong");
  }
}

constexpr int kPngCompressionLevel = 1;
constexpr int kPngFilterSub = 0x10;  // libpng's PNG_FILTER_SUB

// Writes one image through OpenImageIO into `bytes`; the file name only selects the format.
void writeToMemory(const char* fileName, const OIIO::ImageSpec& spec, const void* pixels,
                   std::vector<unsigned char>& bytes) {
  OIIO::Filesystem::IOVecOutput proxy(bytes);
  auto out = OIIO::ImageOutput::create(fileName, &proxy);
  if (!out) throw std::runtime_error("image::encode: no writer for " + std::string(fileName));
  if (!out->supports("ioproxy")) {
    throw std::runtime_error("image::encode: the writer for " + std::string(fileName) +
                             " cannot write to memory");
  }
  if (!out->open(fileName, spec) || !out->write_image(spec.format, pixels) || !out->close()) {
    throw std::runtime_error("image::encode: " + out->geterror());
  }
}

// 8-bit pixels for the lossy formats: JPEG without alpha (RGBA laid over white), WebP with RGB
// or RGBA (grey repeated); `channels` says how many were kept.
std::vector<uint8_t> lossyPixels(const Image& image, const std::string& passName, Format format,
                                 int& channels) {
  const std::vector<uint8_t> bytes = to8Bit(image, passName);
  const int in = image.channels;
  channels = format == Format::Jpeg ? std::min(in, 3) : (in == 4 ? 4 : 3);
  if (format == Format::Jpeg && in == 1) channels = 1;
  std::vector<uint8_t> out(static_cast<size_t>(image.width) * image.height * channels);
  for (size_t p = 0; p < static_cast<size_t>(image.width) * image.height; ++p) {
    const uint8_t* from = &bytes[p * in];
    uint8_t* to = &out[p * channels];
    const float alpha = in == 4 && channels == 3 ? from[3] / 255.0f : 1.0f;
    for (int c = 0; c < channels; ++c) {
      const uint8_t value = from[in == 1 ? 0 : std::min(c, in - 1)];
      to[c] = c < 3 ? static_cast<uint8_t>(value * alpha + 255.0f * (1.0f - alpha) + 0.5f) : value;
    }
  }
  return out;
}

}  // namespace

EncodedImage encode(const Image& image, const std::string& passName, Format format, int quality) {
  checkEncodable(image);
  EncodedImage result;
  result.width = image.width;
  result.height = image.height;
  if (format == Format::Png) {
    if (image.channels > 4) {
      throw std::invalid_argument("image::encode: PNG takes at most 4 channels");
    }
    std::vector<uint8_t> pixels = to8Bit(image, passName);
    OIIO::ImageSpec spec(image.width, image.height, image.channels, OIIO::TypeDesc::UINT8);
    // limn's colours are not premultiplied (the background keeps its RGB under alpha 0):
    // tell OpenImageIO so, or it divides by alpha on the way to PNG's unassociated alpha.
    spec.attribute("oiio:UnassociatedAlpha", 1);
    // zlib level 1 with the "sub" row filter: a 256^2 colour image encodes in about a quarter
    // of the time of OpenImageIO's default (level 6, adaptive filters) for files about 10-30%
    // larger (bench/load_results.md); renders are smooth gradients, which "sub" predicts well.
    spec.attribute("png:compressionLevel", kPngCompressionLevel);
    spec.attribute("compression", "zip:" + std::to_string(kPngCompressionLevel));
    spec.attribute("png:filter", kPngFilterSub);
    writeToMemory("limn.png", spec, pixels.data(), result.bytes);
    result.mime = "image/png";
  } else if (format == Format::Jpeg || format == Format::Webp) {
    int channels = 0;
    std::vector<uint8_t> pixels = lossyPixels(image, passName, format, channels);
    OIIO::ImageSpec spec(image.width, image.height, channels, OIIO::TypeDesc::UINT8);
    spec.attribute("oiio:UnassociatedAlpha", 1);
    spec.attribute("Compression", (format == Format::Jpeg ? "jpeg:" : "webp:") +
                                      std::to_string(std::clamp(quality, 1, 100)));
    const bool jpeg = format == Format::Jpeg;
    writeToMemory(jpeg ? "limn.jpg" : "limn.webp", spec, pixels.data(), result.bytes);
    result.mime = jpeg ? "image/jpeg" : "image/webp";
  } else {
    OIIO::ImageSpec spec(image.width, image.height, image.channels, OIIO::TypeDesc::FLOAT);
    spec.channelnames = exrChannelNames(image.channels, passName);
    spec.attribute("compression", "zip");  // lossless
    writeToMemory("limn.exr", spec, image.pixels.data(), result.bytes);
    result.mime = "image/x-exr";
  }
  return result;
}

EncodedImage encodeAnimation(const std::vector<const Image*>& frames, double fps) {
  if (frames.empty()) throw std::invalid_argument("image::encodeAnimation: no frames");
  const int width = frames[0]->width, height = frames[0]->height;
  std::vector<std::vector<uint8_t>> pixels;
  std::vector<OIIO::ImageSpec> specs;
  for (const Image* frame : frames) {
    checkEncodable(*frame);
    if (frame->width != width || frame->height != height) {
      throw std::invalid_argument("image::encodeAnimation: frames of different sizes");
    }
    int channels = 0;
    pixels.push_back(lossyPixels(*frame, pass::kColor, Format::Jpeg, channels));  // over white
    OIIO::ImageSpec spec(width, height, channels, OIIO::TypeDesc::UINT8);
    const int rate[2] = {static_cast<int>(std::lround(fps * 100)), 100};
    spec.attribute("FramesPerSecond", OIIO::TypeRational, rate);
    spec.attribute("oiio:Movie", 1);
    spec.attribute("gif:LoopCount", 0);  // forever
    specs.push_back(spec);
  }
  EncodedImage result;
  result.width = width;
  result.height = height;
  result.mime = "image/gif";
  OIIO::Filesystem::IOVecOutput proxy(result.bytes);
  auto out = OIIO::ImageOutput::create("limn.gif", &proxy);
  if (!out || !out->supports("ioproxy") || !out->supports("multiimage")) {
    throw std::runtime_error(
        "image::encodeAnimation: OpenImageIO cannot write animated GIF to memory");
  }
  if (!out->open("limn.gif", static_cast<int>(specs.size()), specs.data())) {
    throw std::runtime_error("image::encodeAnimation: " + out->geterror());
  }
  for (size_t f = 0; f < specs.size(); ++f) {
    if ((f > 0 && !out->open("limn.gif", specs[f], OIIO::ImageOutput::AppendSubimage)) ||
        !out->write_image(OIIO::TypeDesc::UINT8, pixels[f].data())) {
      throw std::runtime_error("image::encodeAnimation: " + out->geterror());
    }
  }
  if (!out->close()) throw std::runtime_error("image::encodeAnimation: " + out->geterror());
  return result;
}

Image decode(const std::vector<unsigned char>& bytes) {
  // The reader is chosen by the file's magic number, not by a name.
  static const unsigned char kPngMagic[4] = {0x89, 'P', 'N', 'G'};
  static const unsigned char kExrMagic[4] = {0x76, 0x2f, 0x31, 0x01};
  static const unsigned char kJpegMagic[3] = {0xff, 0xd8, 0xff};
  const char* fileName = nullptr;
  if (bytes.size() >= 4 && std::memcmp(bytes.data(), kPngMagic, 4) == 0) fileName = "limn.png";
  if (bytes.size() >= 4 && std::memcmp(bytes.data(), kExrMagic, 4) == 0) fileName = "limn.exr";
  if (bytes.size() >= 3 && std::memcmp(bytes.data(), kJpegMagic, 3) == 0) fileName = "limn.jpg";
  if (bytes.size() >= 12 && std::memcmp(bytes.data(), "RIFF", 4) == 0 &&
      std::memcmp(bytes.data() + 8, "WEBP", 4) == 0) {
    fileName = "limn.webp";
  }
  if (!fileName) {
    throw std::invalid_argument("image::decode: neither PNG, OpenEXR, JPEG nor WebP data");
  }

  OIIO::Filesystem::IOMemReader proxy(bytes.data(), bytes.size());
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);  // keep PNG colours as stored (see encode)
  // With a configuration spec, OpenImageIO 2.4 takes the proxy from the spec, not the argument.
  void* proxyPointer = &proxy;
  config.attribute("oiio:ioproxy", OIIO::TypeDesc::PTR, &proxyPointer);
  auto in = OIIO::ImageInput::open(fileName, &config, &proxy);
  if (!in) throw std::runtime_error("image::decode: " + OIIO::geterror());
  const OIIO::ImageSpec& spec = in->spec();
  Image image(spec.width, spec.height, spec.nchannels);
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, image.pixels.data())) {
    throw std::runtime_error("image::decode: " + in->geterror());
  }
  in->close();
  return image;
}

}  // namespace limn::render::image
