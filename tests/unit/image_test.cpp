// Tests of render/image: PNG and EXR encoding into memory, decoding, and the 8-bit mappings of
// the depth and normal passes that clients see in PNG answers.
#include "render/core/image.h"

#include <gtest/gtest.h>

#include <cmath>

#include "render/core/shading.h"
#include "render/image/encode.h"
#include "render/image/pixel_mapping.h"

namespace limn::render::image {
namespace {

// A float image whose every value differs, with values outside [0, 1] and a negative zero.
Image gradient(int w, int h, int c) {
  Image img(w, h, c);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int k = 0; k < c; ++k) img.at(x, y, k) = 0.013f * x - 0.007f * y + 0.31f * k - 0.1f;
  return img;
}

TEST(ImageEncode, ExrRoundTripIsExactForEveryChannelCount) {
  for (int c : {1, 3, 4}) {
    Image img = gradient(37, 23, c);
    img.at(0, 0, 0) = 1234.5678f;
    img.at(1, 0, 0) = -3.25e-5f;
    EncodedImage enc = encode(img, c == 1 ? pass::kDepth : pass::kColor, Format::Exr);
    EXPECT_EQ(enc.mime, "image/x-exr");
    EXPECT_EQ(enc.width, 37);
    EXPECT_EQ(enc.height, 23);
    Image back = decode(enc.bytes);
    ASSERT_EQ(back.width, 37);
    ASSERT_EQ(back.height, 23);
    ASSERT_EQ(back.channels, c);
    EXPECT_EQ(back.pixels, img.pixels) << c << " channels";
  }
}

// The colour passes hold linear light and are written as sRGB (alpha as it is): decoded, a PNG
// gives the sRGB values back, within the 8-bit step.
TEST(ImageEncode, PngColorRoundTripWithinOneLevel) {
  Image img(16, 9, 4);
  for (int y = 0; y < 9; ++y)
    for (int x = 0; x < 16; ++x) {
      img.at(x, y, 0) = x / 15.0f;
      img.at(x, y, 1) = y / 8.0f;
      img.at(x, y, 2) = 0.123f;
      img.at(x, y, 3) = (x + y) % 2;
    }
  EncodedImage enc = encode(img, pass::kColor, Format::Png);
  EXPECT_EQ(enc.mime, "image/png");
  ASSERT_GT(enc.bytes.size(), 8u);
  EXPECT_EQ(enc.bytes[1], 'P');
  Image back = decode(enc.bytes);
  ASSERT_EQ(back.channels, 4);
  ASSERT_EQ(back.width, 16);
  ASSERT_EQ(back.height, 9);
  for (size_t i = 0; i < img.pixels.size(); ++i) {
    const float expected = i % 4 == 3 ? img.pixels[i] : shading::linearToSrgb(img.pixels[i]);
    EXPECT_NEAR(back.pixels[i], expected, 1.0f / 255.0f + 1e-6f) << i;
  }
  // Mid-grey light is sRGB 188, not 128.
  Image grey(1, 1, 4, 0.5f);
  EXPECT_EQ(to8Bit(grey, pass::kColor), (std::vector<uint8_t>{188, 188, 188, 128}));
  EXPECT_EQ(to8Bit(grey, pass::kDiff), (std::vector<uint8_t>{128, 128, 128, 128}));
  // Out of range and NaN clamp, in colour channels and alpha alike; 3 channels have no alpha.
  Image edges(2, 1, 4);
  edges.pixels = {-0.5f, 0.0f, 1.0f, std::nanf(""), 2.0f, 1e-9f, 0.999999f, 1.5f};
  EXPECT_EQ(to8Bit(edges, pass::kColor), (std::vector<uint8_t>{0, 0, 255, 0, 255, 0, 255, 255}));
  Image rgb(2, 1, 3);
  rgb.pixels = {0.5f, std::nanf(""), 3.0f, 0.0f, 0.5f, -1.0f};
  EXPECT_EQ(to8Bit(rgb, pass::kColor), (std::vector<uint8_t>{188, 0, 255, 0, 188, 0}));
  // Row 0 stays the top row.
  EXPECT_NEAR(back.at(0, 8, 1), 1.0f, 1e-6f);
  EXPECT_NEAR(back.at(0, 0, 1), 0.0f, 1e-6f);
}

TEST(ImageEncode, PngClampsOutOfRangeColor) {
  Image img(2, 1, 4, 0.5f);
  img.at(0, 0, 0) = 7.0f;
  img.at(1, 0, 0) = -2.0f;
  Image back = decode(encode(img, pass::kWireframe, Format::Png).bytes);
  EXPECT_FLOAT_EQ(back.at(0, 0, 0), 1.0f);
  EXPECT_FLOAT_EQ(back.at(1, 0, 0), 0.0f);
}

TEST(ImageEncode, PngMaskIsGrey) {
  Image mask(5, 4, 1, 0.0f);
  mask.at(2, 1) = 1.0f;
  mask.at(4, 3) = 1.0f;
  Image back = decode(encode(mask, pass::kMask, Format::Png).bytes);
  ASSERT_EQ(back.channels, 1);
  EXPECT_EQ(back.pixels, mask.pixels);
}

TEST(ImageEncode, PngDepthNearestWhiteFarthestDarkEmptyBlack) {
  Image depth(4, 1, 1, 0.0f);
  depth.at(0, 0) = 2.0f;  // nearest
  depth.at(1, 0) = 3.0f;  // midway
  depth.at(2, 0) = 4.0f;  // farthest
  Image back = decode(encode(depth, pass::kDepth, Format::Png).bytes);
  ASSERT_EQ(back.channels, 1);
  EXPECT_FLOAT_EQ(back.at(0, 0), 1.0f);
  EXPECT_NEAR(back.at(2, 0), kFarthestDepthGrey, 0.5f / 255.0f);
  EXPECT_GT(back.at(2, 0), 0.0f);  // the farthest surface is not the background
  EXPECT_NEAR(back.at(1, 0), 1.0f - 0.5f * (1.0f - kFarthestDepthGrey), 0.5f / 255.0f);
  EXPECT_FLOAT_EQ(back.at(3, 0), 0.0f);
}

TEST(ImageEncode, PngDepthOfOneDistanceIsWhite) {
  Image depth(3, 1, 1, 0.0f);
  depth.at(1, 0) = 5.0f;
  depth.at(2, 0) = 5.0f;
  std::vector<uint8_t> grey = to8Bit(depth, pass::kDepth);
  EXPECT_EQ(grey, (std::vector<uint8_t>{0, 255, 255}));
}

TEST(ImageEncode, PngNormalMapsToHalfOffsetRgb) {
  Image normal(3, 1, 3, 0.0f);
  normal.at(0, 0, 2) = 1.0f;   // +Z
  normal.at(1, 0, 0) = -1.0f;  // -X
  // pixel 2 stays empty: zero-length normal
  Image back = decode(encode(normal, pass::kNormal, Format::Png).bytes);
  ASSERT_EQ(back.channels, 3);
  const float half = 128.0f / 255.0f;
  EXPECT_NEAR(back.at(0, 0, 0), half, 1e-6f);
  EXPECT_NEAR(back.at(0, 0, 1), half, 1e-6f);
  EXPECT_FLOAT_EQ(back.at(0, 0, 2), 1.0f);
  EXPECT_FLOAT_EQ(back.at(1, 0, 0), 0.0f);
  EXPECT_NEAR(back.at(1, 0, 1), half, 1e-6f);
  for (int k = 0; k < 3; ++k) EXPECT_FLOAT_EQ(back.at(2, 0, k), 0.0f);
}

TEST(ImageEncode, ExrKeepsDepthValuesAsTheyAre) {
  Image depth(2, 2, 1, 0.0f);
  depth.at(1, 1) = 3.14159265f;
  Image back = decode(encode(depth, pass::kDepth, Format::Exr).bytes);
  EXPECT_EQ(back.pixels, depth.pixels);
}

TEST(ImageEncode, RejectsEmptyImagesAndGarbage) {
  EXPECT_THROW(encode(Image(), pass::kColor, Format::Png), std::invalid_argument);
  EXPECT_THROW(encode(Image(2, 2, 5), pass::kColor, Format::Png), std::invalid_argument);
  EXPECT_THROW(decode({1, 2, 3, 4, 5}), std::invalid_argument);
  std::vector<unsigned char> truncated = encode(gradient(8, 8, 4), pass::kColor, Format::Png).bytes;
  truncated.resize(truncated.size() / 2);
  EXPECT_THROW(decode(truncated), std::runtime_error);
}

}  // namespace
}  // namespace limn::render::image
