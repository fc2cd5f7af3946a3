#include <algorithm>
#include <cmath>

#include "render/core/parallel.h"
#include "render/implicit/cube_table.h"
#include "render/implicit/grid.h"

namespace limn::render::implicit {

namespace {
constexpr uint32_t kNone = UINT32_MAX;
}

Grid makeGrid(const Bounds& domain, int resolution) {
  const Vec3 size = domain.hi - domain.lo;
  const double longest = std::max({size.x, size.y, size.z, 1e-300});
  Grid grid;
  grid.cell = longest / resolution;
  for (int a = 0; a < 3; ++a) {
    grid.n[a] = static_cast<int>(std::ceil(size[a] / grid.cell - 1e-9)) + 2;
    grid.n[a] = std::max(grid.n[a], 2);
  }
  // Centre the grid on the domain.
  const Vec3 span{grid.n[0] * grid.cell, grid.n[1] * grid.cell, grid.n[2] * grid.cell};
  grid.origin = domain.center() - span * 0.5;
  return grid;
}

void sampleLayers(const Field& field, const Grid& grid, int k0, int k1, float* out,
                  const CancelToken& cancel) {
  const int nx = grid.n[0] + 1, ny = grid.n[1] + 1;
  const size_t rows = static_cast<size_t>(k1 - k0 + 1) * ny;
  parallelFor(rows, 16, [&](size_t begin, size_t end) {
    if (cancel.expired()) return;
    FieldEvaluator evaluator(field);
    for (size_t row = begin; row < end; ++row) {
      const int k = k0 + static_cast<int>(row / ny), j = static_cast<int>(row % ny);
      float* values = out + row * nx;
      for (int i = 0; i < nx; ++i) {
        values[i] = static_cast<float>(evaluator.value(grid.corner(i, j, k)));
      }
    }
  });
  cancel.check();
}

LayerMarcher::LayerMarcher(const Grid& grid, RawMesh& out) : grid_(grid), out_(out) {
  const size_t nx = grid.n[0], ny = grid.n[1];
  xBottom_.assign(nx * (ny + 1), kNone);
  xTop_ = xBottom_;
  yBottom_.assign((nx + 1) * ny, kNone);
  yTop_ = yBottom_;
  z_.assign((nx + 1) * (ny + 1), kNone);
}

void LayerMarcher::march(int k, const float* bottom, const float* top) {
  const int nx = grid_.n[0], ny = grid_.n[1];
  const size_t stride = nx + 1;
  const CubeTable& table = CubeTable::instance();
  const auto& edges = cubeEdges();
  std::fill(z_.begin(), z_.end(), kNone);
  // Per column of corners (x = i) of a row of cells: the inside bits of its four corners at the
  // places they take in a cube's configuration (bits 0, 2, 4, 6: y0z0, y1z0, y0z1, y1z1), so a
  // cell's configuration is column[i] | column[i + 1] << 1, and empty cells cost two loads.
  columns_.resize(stride);
  for (int j = 0; j < ny; ++j) {
    const float* b0 = bottom + j * stride;
    const float* b1 = b0 + stride;
    const float* t0 = top + j * stride;
    const float* t1 = t0 + stride;
    for (size_t i = 0; i < stride; ++i) {
      columns_[i] = static_cast<uint8_t>((b0[i] > 0.0f) | (b1[i] > 0.0f) << 2 |
                                         (t0[i] > 0.0f) << 4 | (t1[i] > 0.0f) << 6);
    }
    for (int i = 0; i < nx; ++i) {
      const int configuration = columns_[i] | columns_[i + 1] << 1;
      if (configuration == 0 || configuration == 255) continue;
      ++cellsWithSurface_;
      const size_t c00 = j * stride + i;
      const float v[8] = {
          bottom[c00], bottom[c00 + 1], bottom[c00 + stride], bottom[c00 + stride + 1],
          top[c00],    top[c00 + 1],    top[c00 + stride],    top[c00 + stride + 1]};
      const std::vector<uint8_t>& triangles = table.triangles(configuration);
      for (uint8_t e : triangles) {
        // The slot of edge e of cell (i, j) among the two layers' edge arrays.
        uint32_t* slot;
        const CubeEdge& edge = edges[e];
        const int ca = edge.a;
        const int di = ca & 1, dj = (ca >> 1) & 1, dk = (ca >> 2) & 1;
        switch (edge.axis) {
          case 0:
            slot = &(dk ? xTop_ : xBottom_)[(j + dj) * static_cast<size_t>(nx) + i];
            break;
          case 1:
            slot = &(dk ? yTop_ : yBottom_)[(j)*stride + i + di];
            break;
          default:
            slot = &z_[(j + dj) * stride + i + di];
            break;
        }
        if (*slot == kNone) {
          const int cb = edge.b;
          *slot = out_.addVertex(
              grid_.corner(i + di, j + dj, k + dk),
              grid_.corner(i + (cb & 1), j + ((cb >> 1) & 1), k + ((cb >> 2) & 1)), v[ca], v[cb]);
        }
        out_.indices.push_back(*slot);
      }
    }
  }
  // The top layer's x and y edges are the next layer's bottom ones.
  std::swap(xBottom_, xTop_);
  std::swap(yBottom_, yTop_);
  std::fill(xTop_.begin(), xTop_.end(), kNone);
  std::fill(yTop_.begin(), yTop_.end(), kNone);
}

}  // namespace limn::render::implicit
