#include "render/image/encode.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

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

}  // namespace

EncodedImage encode(const Image& image, const std::string& passName, Format format) {
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
  } else {
    OIIO::ImageSpec spec(image.width, image.height, image.channels, OIIO::TypeDesc::FLOAT);
    spec.channelnames = exrChannelNames(image.channels, passName);
    spec.attribute("compression", "zip");  // lossless
    writeToMemory("limn.exr", spec, image.pixels.data(), result.bytes);
    result.mime = "image/x-exr";
  }
  return result;
}

Image decode(const std::vector<unsigned char>& bytes) {
  // The reader is chosen by the file's magic number, not by a name.
  static const unsigned char kPngMagic[4] = {0x89, 'P', 'N', 'G'};
  static const unsigned char kExrMagic[4] = {0x76, 0x2f, 0x31, 0x01};
  const char* fileName = nullptr;
  if (bytes.size() >= 4 && std::memcmp(bytes.data(), kPngMagic, 4) == 0) fileName = "limn.png";
  if (bytes.size() >= 4 && std::memcmp(bytes.data(), kExrMagic, 4) == 0) fileName = "limn.exr";
  if (!fileName) throw std::invalid_argument("image::decode: neither PNG nor OpenEXR data");

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
