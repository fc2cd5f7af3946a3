// Exact Euclidean nearest-feature transform: for every pixel of a binary image, the index of
// the feature pixel nearest to it. It is the distance transform of Felzenszwalb & Huttenlocher
// ("Distance Transforms of Sampled Functions") keeping the argument of each minimum, not only
// the distance: pass 1 finds the nearest feature row in each column, pass 2 the lower envelope
// of the parabolas (x - q)^2 + (y - row_q)^2 along each row. Both passes run in parallel.
//
// The normal atlas uses it to dilate charts: every texel outside a chart's domain takes the
// value of the nearest texel inside one, so bilinear sampling never reads an empty texel.
#pragma once

#include <cstdint>
#include <vector>

namespace limn::render::normalmap {

// `feature` is row-major, width x height, non-zero for feature pixels. Returns, row-major, the
// index y * width + x of the nearest feature pixel of each pixel (itself for features), or -1
// everywhere when there is no feature. Ties go to any of the nearest. Throws
// std::invalid_argument for negative sizes or a mask of the wrong size.
std::vector<int64_t> nearestFeature(const std::vector<uint8_t>& feature, int width, int height);

}  // namespace limn::render::normalmap
