#include "render/normalmap/normal_atlas.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "render/core/error.h"
#include "render/core/parallel.h"
#include "render/normalmap/nearest_feature.h"

namespace limn::render::normalmap {

namespace {

using OpenSubdiv::Bfr::Parameterization;

int gridColumns(int charts) {
  int columns = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(charts))));
  while (static_cast<long long>(columns) * columns < charts) ++columns;  // rounding
  return std::max(columns, 1);
}

// Charts of one face: its sub-faces, or one.
int chartsOfFace(const subdiv::LimitSurface& surface, int face) {
  if (!surface.hasLimit(face)) return 0;
  const Parameterization p = surface.parameterization(face);
  return p.HasSubFaces() ? p.GetFaceSize() : 1;
}

}  // namespace

int NormalAtlas::chartCountOf(const subdiv::LimitSurface& surface) {
  int count = 0;
  for (int f = 0; f < surface.faceCount(); ++f) count += chartsOfFace(surface, f);
  return count;
}

int NormalAtlas::sideFor(int charts, int chartTexels) {
  const long long columns = gridColumns(charts);
  const long long side = columns * chartTexels + (columns - 1) * kGutter;
  return static_cast<int>(std::min<long long>(side, 1LL << 30));
}

NormalAtlas::NormalAtlas(const subdiv::LimitSurface& surface, int chartTexels, int maxSide)
    : chartTexels_(chartTexels) {
  if (chartTexels < kMinChartTexels) {
    throw std::invalid_argument("normalmap: charts need at least " +
                                std::to_string(kMinChartTexels) + " texels on a side");
  }
  layOut(surface, maxSide);
  bake(surface);
}

void NormalAtlas::layOut(const subdiv::LimitSurface& surface, int maxSide) {
  firstChart_.assign(surface.faceCount(), -1);
  parameterizations_.resize(surface.faceCount());
  for (int f = 0; f < surface.faceCount(); ++f) {
    const int n = chartsOfFace(surface, f);
    if (n == 0) continue;
    firstChart_[f] = static_cast<int>(charts_.size());
    const Parameterization p = surface.parameterization(f);
    parameterizations_[f] = p;
    for (int k = 0; k < n; ++k) {
      Chart chart;
      chart.face = f;
      chart.subFace = p.HasSubFaces() ? k : -1;
      chart.triangle = p.GetType() == Parameterization::TRI;
      charts_.push_back(chart);
    }
  }
  const int count = static_cast<int>(charts_.size());
  const int side = sideFor(std::max(count, 1), chartTexels_);
  if (side > maxSide) {
    throw InputError(InputError::Kind::LimitExceeded, "maxAtlasSide",
                     "the normal atlas of " + std::to_string(count) + " charts of " +
                         std::to_string(chartTexels_) + " texels would be " + std::to_string(side) +
                         " texels wide, more than the limit of " + std::to_string(maxSide));
  }
  const int columns = gridColumns(std::max(count, 1));
  const int rows = std::max(1, (count + columns - 1) / columns);
  const int pitch = chartTexels_ + kGutter;
  for (int c = 0; c < count; ++c) {
    charts_[c].x = (c % columns) * pitch;
    charts_[c].y = (c / columns) * pitch;
  }
  if (count == 0) {
    image_ = std::make_shared<Image>(1, 1, 3);
    image_->at(0, 0, 2) = 1.0f;
    return;
  }
  image_ = std::make_shared<Image>(side, rows * pitch - kGutter, 3);
}

void NormalAtlas::bake(const subdiv::LimitSurface& surface) {
  if (charts_.empty()) return;
  Image& image = *image_;
  const int n = chartTexels_;
  const double step = 1.0 / (n - 1);
  std::vector<uint8_t> inside(static_cast<size_t>(image.width) * image.height, 0);
  parallelFor(charts_.size(), 4, [&](size_t begin, size_t end) {
    for (size_t c = begin; c < end; ++c) {
      const Chart& chart = charts_[c];
      const Parameterization p = surface.parameterization(chart.face);
      for (int j = 0; j < n; ++j) {
        for (int i = 0; i < n; ++i) {
          if (chart.triangle && i + j > n - 1) continue;  // outside u + v <= 1
          double uv[2] = {i * step, j * step};
          if (chart.subFace >= 0) {
            const double st[2] = {uv[0], uv[1]};
            p.ConvertNormalizedSubFaceToCoord(chart.subFace, st, uv);
          }
          const Vec3 normal = surface.evaluate(chart.face, uv[0], uv[1]).normal;
          const int x = chart.x + i, y = chart.y + j;
          for (int k = 0; k < 3; ++k) image.at(x, y, k) = static_cast<float>(normal[k]);
          inside[static_cast<size_t>(y) * image.width + x] = 1;
        }
      }
    }
  });
  // Dilation: every texel outside the domains copies its nearest texel inside one.
  const std::vector<int64_t> nearest = nearestFeature(inside, image.width, image.height);
  parallelFor(inside.size(), 1 << 14, [&](size_t begin, size_t end) {
    for (size_t t = begin; t < end; ++t) {
      if (inside[t] || nearest[t] < 0) continue;
      const size_t from = static_cast<size_t>(nearest[t]);
      for (int k = 0; k < 3; ++k) image.pixels[t * 3 + k] = image.pixels[from * 3 + k];
    }
  });
}

bool NormalAtlas::hasChart(int face) const {
  return face >= 0 && face < static_cast<int>(firstChart_.size()) && firstChart_[face] >= 0;
}

Vec2f NormalAtlas::chartCoordinate(const Chart& chart, double s, double t) const {
  // Texel i's centre is at (x + i + 0.5) / width, and s = i / (n - 1) lands on it.
  const double span = chartTexels_ - 1;
  const double x = chart.x + 0.5 + std::clamp(s, 0.0, 1.0) * span;
  const double y = chart.y + 0.5 + std::clamp(t, 0.0, 1.0) * span;
  return {static_cast<float>(x / image_->width), static_cast<float>(y / image_->height)};
}

Vec2f NormalAtlas::coordinate(int face, Vec2 uv) const {
  if (!hasChart(face)) {
    throw std::invalid_argument("normalmap: face " + std::to_string(face) + " has no chart");
  }
  const Chart& first = charts_[firstChart_[face]];
  if (first.subFace < 0) return chartCoordinate(first, uv.x, uv.y);
  const double in[2] = {uv.x, uv.y};
  double st[2];
  const int subFace = parameterizations_[face].ConvertCoordToNormalizedSubFace(in, st);
  return subFaceCoordinate(face, subFace, {st[0], st[1]});
}

Vec2f NormalAtlas::subFaceCoordinate(int face, int subFace, Vec2 st) const {
  if (!hasChart(face)) {
    throw std::invalid_argument("normalmap: face " + std::to_string(face) + " has no chart");
  }
  const size_t index = static_cast<size_t>(firstChart_[face]) + std::max(subFace, 0);
  if (subFace < 0 || index >= charts_.size() || charts_[index].face != face ||
      (subFace > 0 && charts_[index].subFace != subFace)) {
    throw std::invalid_argument("normalmap: face " + std::to_string(face) + " has no sub-face " +
                                std::to_string(subFace));
  }
  return chartCoordinate(charts_[index], st.x, st.y);
}

int chartTexelsForBudget(const subdiv::LimitSurface& surface, size_t texelBudget, int maxSide,
                         int maxChartTexels) {
  const int charts = std::max(NormalAtlas::chartCountOf(surface), 1);
  int best = NormalAtlas::kMinChartTexels;
  for (int n = NormalAtlas::kMinChartTexels + 1; n <= maxChartTexels; ++n) {
    const size_t pitch = static_cast<size_t>(n + NormalAtlas::kGutter);
    if (NormalAtlas::sideFor(charts, n) > maxSide) break;
    if (static_cast<size_t>(charts) * pitch * pitch > texelBudget) break;
    best = n;
  }
  return best;
}

int chartTexelsForCamera(const subdiv::LimitSurface& surface, const Camera& camera,
                         double texelsPerPixel, size_t texelBudget, int maxSide,
                         int maxChartTexels) {
  double largest = 0;  // projected length in pixels of the longest chart side
  for (int f = 0; f < surface.faceCount(); ++f) {
    if (!surface.hasLimit(f)) continue;
    const Parameterization p = surface.parameterization(f);
    const int corners = p.GetFaceSize();
    std::vector<Vec3> points;
    for (int k = 0; k < corners; ++k) {
      const Vec2 uv = surface.cornerUV(f, k);
      points.push_back(surface.position(f, uv.x, uv.y));
    }
    const Vec2 c = surface.centerUV(f);
    const Vec3 centre = surface.position(f, c.x, c.y);
    auto projectedLength = [&](const Vec3& a, const Vec3& b) {
      if (camera.depthOf(a) <= camera.nearPlane() || camera.depthOf(b) <= camera.nearPlane()) {
        return 0.0;
      }
      const Vec3 pa = camera.project(a), pb = camera.project(b);
      return std::hypot(pa.x - pb.x, pa.y - pb.y);
    };
    for (int k = 0; k < corners; ++k) {
      const Vec3& a = points[k];
      const Vec3& b = points[(k + 1) % corners];
      // A sub-face spans half of each of its two edges and reaches the centre.
      const double scale = p.HasSubFaces() ? 0.5 : 1.0;
      largest = std::max(largest, scale * projectedLength(a, b));
      if (p.HasSubFaces()) largest = std::max(largest, projectedLength(a, centre));
    }
  }
  const int wanted = static_cast<int>(std::ceil(texelsPerPixel * largest)) + 1;
  const int cap = chartTexelsForBudget(surface, texelBudget, maxSide, maxChartTexels);
  return std::clamp(wanted, NormalAtlas::kMinChartTexels, cap);
}

}  // namespace limn::render::normalmap
