#include <algorithm>
#include <cmath>
#include <stdexcept>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "render/core/parallel.h"
#include "render/implicit/cube_table.h"
#include "render/implicit/grid.h"

namespace limn::render::implicit {

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

namespace {

// Bit i of a row's word w is corner i = 64 w + i; the last word of every row is zero padding,
// so reading word w + 1 is always allowed for a real word w.

// The inside bits (value > 0) of `count` <= 64 consecutive corners. NaN and exactly 0 are
// outside, as cubeConfiguration has them.
uint64_t insideBits(const float* values, int count) {
  uint64_t bits = 0;
  int b = 0;
#if defined(__SSE2__)
  // 16 corners per step: four compares packed to bytes, one movemask.
  const __m128 zero = _mm_setzero_ps();
  auto inside = [&](int at) {
    return _mm_castps_si128(_mm_cmpgt_ps(_mm_loadu_ps(values + at), zero));
  };
  for (; b + 16 <= count; b += 16) {
    const __m128i low = _mm_packs_epi32(inside(b), inside(b + 4));
    const __m128i high = _mm_packs_epi32(inside(b + 8), inside(b + 12));
    bits |= static_cast<uint64_t>(_mm_movemask_epi8(_mm_packs_epi16(low, high))) << b;
  }
  for (; b + 4 <= count; b += 4) {
    bits |= static_cast<uint64_t>(_mm_movemask_ps(_mm_castsi128_ps(inside(b)))) << b;
  }
#endif
  for (; b < count; ++b) bits |= static_cast<uint64_t>(values[b] > 0.0f) << b;
  return bits;
}

// The bits of corners i + 1 at places i.
inline uint64_t nextCorners(const uint64_t* row, int w) {
  return (row[w] >> 1) | (row[w + 1] << 63);
}

// Corners i and i + 1 as bits 0 and 1.
inline int cornerPair(const uint64_t* row, int i) {
  const int w = i >> 6, b = i & 63;
  return static_cast<int>(((row[w] >> b) | ((row[w + 1] << 1) << (63 - b))) & 3);
}

// Set bits of a word: the popcnt instruction where the build targets it, else the same in a
// dozen inline operations (a library call per word costs more than the rest of the loop).
inline uint32_t bitCount(uint64_t x) {
#if defined(__POPCNT__)
  return static_cast<uint32_t>(__builtin_popcountll(x));
#else
  x = x - ((x >> 1) & 0x5555555555555555ull);
  x = (x & 0x3333333333333333ull) + ((x >> 2) & 0x3333333333333333ull);
  x = (x + (x >> 4)) & 0x0f0f0f0f0f0f0f0full;
  return static_cast<uint32_t>((x * 0x0101010101010101ull) >> 56);
#endif
}

inline uint64_t bitsBelow(int b) { return (uint64_t{1} << b) - 1; }

template <typename Visit>  // Visit: void(int i) for each set bit i, in increasing order
void forEachBit(uint64_t word, int w, const Visit& visit) {
  while (word) {
    visit(64 * w + __builtin_ctzll(word));
    word &= word - 1;
  }
}

// The marching-cubes table flattened for the inner loop, with each cube edge's place among the
// eight edge masks of a row of cells (CellRow) and its x offset from the cell's corner 0.
struct CaseTable {
  uint16_t begin[257];
  uint16_t crossed[256];  // the cube edges the configuration's triangles use
  std::vector<uint8_t> edges;
  uint8_t mask[12], dx[12];

  static const CaseTable& instance() {
    static const CaseTable table;
    return table;
  }

 private:
  CaseTable() {
    const CubeTable& cubes = CubeTable::instance();
    for (int c = 0; c < 256; ++c) {
      begin[c] = static_cast<uint16_t>(edges.size());
      edges.insert(edges.end(), cubes.triangles(c).begin(), cubes.triangles(c).end());
      crossed[c] = 0;
      for (uint8_t e : cubes.triangles(c)) crossed[c] |= static_cast<uint16_t>(1u << e);
    }
    begin[256] = static_cast<uint16_t>(edges.size());
    for (int e = 0; e < 12; ++e) {
      const CubeEdge& edge = cubeEdges()[e];
      const int dy = (edge.a >> 1) & 1, dz = (edge.a >> 2) & 1;
      const int masks[3] = {dy + 2 * dz, 4 + dz, 6 + dy};  // x of a..d, y of a, c, z of a, b
      mask[e] = static_cast<uint8_t>(masks[edge.axis]);
      dx[e] = static_cast<uint8_t>(edge.a & 1);
    }
  }
};

}  // namespace

// The four rows of corners around a row of cells: a (j, k), b (j + 1, k), c (j, k + 1),
// d (j + 1, k + 1), i.e. a cube's corners 0-1, 2-3, 4-5, 6-7.
struct SlabMarcher::CellRow {
  const uint64_t *a, *b, *c, *d;
  int realWords;
  uint64_t lastCells;  // the cells of the last real word (cells i < n0)

  uint64_t cellMask(int w) const { return w + 1 == realWords ? lastCells : ~uint64_t{0}; }
  uint64_t xEdges(const uint64_t* row, int w) const {
    return (row[w] ^ nextCorners(row, w)) & cellMask(w);
  }
  uint64_t mixedColumns(int w) const { return (a[w] ^ b[w]) | (a[w] ^ c[w]) | (a[w] ^ d[w]); }
  // The cells whose eight corners do not all agree.
  uint64_t surfaceCells(int w) const {
    const uint64_t mixed = mixedColumns(w), mixedNext = (mixed >> 1) | (mixedColumns(w + 1) << 63);
    return (mixed | mixedNext | (a[w] ^ nextCorners(a, w))) & cellMask(w);
  }
  int configuration(int i) const {
    return cornerPair(a, i) | cornerPair(b, i) << 2 | cornerPair(c, i) << 4 | cornerPair(d, i) << 6;
  }
};

struct SlabMarcher::Slab {
  int k0, k1;
  const float* values;
  int layers;   // corner layers, k1 - k0 + 1
  size_t rows;  // rows of corners
  bool last;    // k1 is the grid's last layer: its x and y edges are this slab's to write
};

SlabMarcher::SlabMarcher(const Grid& grid, RawMesh& out)
    : grid_(grid), out_(out), words_((grid.n[0] + 1 + 63) / 64 + 1) {
  if (grid.n[0] + 1 > UINT16_MAX)
    throw std::length_error("marching cubes: rows over 65,535 corners");
}

void SlabMarcher::march(int k0, int k1, const float* values) {
  const int layers = k1 - k0 + 1;
  const Slab slab{
      k0, k1, values, layers, static_cast<size_t>(layers) * (grid_.n[1] + 1), k1 == grid_.n[2]};
  bits_.resize(slab.rows * words_);
  xyVertex_.resize(slab.rows);
  zVertex_.resize(slab.rows);
  triangle_.resize(slab.rows);
  work_.resize(slab.rows);
  state_.resize(slab.rows);
  xVertices_.resize(slab.rows);
  ranks_.resize(slab.rows * 3 * (words_ - 1));
  classify(slab);
  count(slab);
  assignOffsets(slab);
  write(slab);
}

// Rows handed to a thread at a time: about 2^18 corners, so that a small grid, whose passes
// take less than starting a thread does (0.1-0.3 ms on the development VM), runs on one.
size_t SlabMarcher::rowsPerTask() const {
  return std::max<size_t>(16, (size_t{1} << 18) / (grid_.n[0] + 1));
}

void SlabMarcher::classify(const Slab& slab) {
  const int nx = grid_.n[0] + 1;
  parallelFor(slab.rows, rowsPerTask(), [&](size_t begin, size_t end) {
    for (size_t r = begin; r < end; ++r) {
      const float* values = slab.values + r * nx;
      uint64_t* row = &bits_[r * words_];
      uint64_t any = 0, all = ~uint64_t{0};
      for (int w = 0; w < words_; ++w) {
        const int count = std::clamp(nx - 64 * w, 0, 64);
        row[w] = insideBits(values + 64 * w, count);
        any |= row[w];
        if (count > 0) all &= row[w] | ~bitsBelow(count - 1) << 1;  // count - 1: no shift by 64
      }
      state_[r] = any == 0 ? kAllOutside : ~all == 0 ? kAllInside : kMixed;
    }
  });
}

SlabMarcher::CellRow SlabMarcher::cellRow(size_t r, bool withNeighbours) const {
  const size_t layerWords = static_cast<size_t>(grid_.n[1] + 1) * words_;
  const uint64_t* a = &bits_[r * words_];
  const int realWords = words_ - 1;
  const uint64_t lastCells = bitsBelow(grid_.n[0] - 64 * (realWords - 1));
  if (!withNeighbours) return {a, nullptr, nullptr, nullptr, realWords, lastCells};
  return {a, a + words_, a + layerWords, a + layerWords + words_, realWords, lastCells};
}

// Whether row r and the rows it reaches to (j + 1, k + 1, both) are all inside or all outside:
// then it owns no crossed edge and its row of cells has no surface, and the row is not read.
bool SlabMarcher::uniform(size_t r, bool nextRow, bool nextLayer) const {
  const uint8_t state = state_[r];
  const size_t ny = grid_.n[1] + 1;
  return state != kMixed && (!nextRow || state_[r + 1] == state) &&
         (!nextLayer || state_[r + ny] == state) &&
         (!(nextRow && nextLayer) || state_[r + ny + 1] == state);
}

void SlabMarcher::count(const Slab& slab) {
  const int ny = grid_.n[1] + 1;
  const CaseTable& table = CaseTable::instance();
  parallelFor(slab.rows, rowsPerTask(), [&](size_t begin, size_t end) {
    for (size_t r = begin; r < end; ++r) {
      const bool nextRow = static_cast<int>(r % ny) + 1 < ny;
      const bool nextLayer = static_cast<int>(r / ny) + 1 < slab.layers;
      if (uniform(r, nextRow, nextLayer)) {
        xyVertex_[r] = zVertex_[r] = triangle_[r] = 0;
        work_[r] = 0;
        continue;
      }
      const uint64_t* a = &bits_[r * words_];
      const CellRow row = cellRow(r, nextRow && nextLayer);
      uint16_t* rank = &ranks_[r * 3 * row.realWords];
      uint32_t x = 0, y = 0, z = 0, triangles = 0;
      for (int w = 0; w < row.realWords; ++w) {
        rank[w] = static_cast<uint16_t>(x);
        rank[w + row.realWords] = static_cast<uint16_t>(y);
        rank[w + 2 * row.realWords] = static_cast<uint16_t>(z);
        const uint64_t xEdges = row.xEdges(a, w), yEdges = nextRow ? a[w] ^ a[w + words_] : 0,
                       zEdges = nextLayer ? a[w] ^ a[w + (ny * words_)] : 0;
        // Most words of most rows cross nothing: test before counting.
        if (xEdges | yEdges | zEdges) {
          x += bitCount(xEdges);
          y += bitCount(yEdges);
          z += bitCount(zEdges);
        }
        if (!(nextRow && nextLayer)) continue;
        forEachBit(row.surfaceCells(w), w, [&](int i) {
          const int c = row.configuration(i);
          triangles += (table.begin[c + 1] - table.begin[c]) / 3;
        });
      }
      xVertices_[r] = x;
      const uint32_t xy = x + y;
      xyVertex_[r] = xy;
      zVertex_[r] = z;
      triangle_[r] = triangles;
      work_[r] = static_cast<uint8_t>((xy ? kXYVertices : 0) | (z ? kZVertices : 0) |
                                      (triangles ? kTriangles : 0));
    }
  });
}

// Layer by layer: its rows' x and y vertices, then its rows' z vertices. The slab's last layer
// gets its x and y offsets (its cells' triangles use them) but is numbered again, identically,
// as the next slab's first layer, which writes its vertices.
void SlabMarcher::assignOffsets(const Slab& slab) {
  const size_t ny = grid_.n[1] + 1;
  uint32_t vertex = layerVertex_;
  auto number = [&](std::vector<uint32_t>& counts, size_t layer) {
    for (size_t r = layer * ny; r < (layer + 1) * ny; ++r) {
      const uint32_t n = counts[r];
      counts[r] = vertex;
      vertex += n;
    }
  };
  for (int layer = 0; layer + 1 < slab.layers; ++layer) {
    number(xyVertex_, layer);
    number(zVertex_, layer);
  }
  layerVertex_ = vertex;
  number(xyVertex_, slab.layers - 1);
  out_.vertices.resize(slab.last ? vertex : layerVertex_);

  uint32_t triangle = static_cast<uint32_t>(out_.indices.size() / 3);
  for (size_t r = 0; r < slab.rows; ++r) {
    const uint32_t n = triangle_[r];
    triangle_[r] = triangle;
    triangle += n;
  }
  out_.indices.resize(static_cast<size_t>(triangle) * 3);
}

void SlabMarcher::write(const Slab& slab) {
  const int ny = grid_.n[1] + 1;
  parallelFor(slab.rows, rowsPerTask(), [&](size_t begin, size_t end) {
    for (size_t r = begin; r < end; ++r) {
      if (!work_[r]) continue;
      const bool nextLayer = static_cast<int>(r / ny) + 1 < slab.layers;
      if ((work_[r] & kXYVertices) && (nextLayer || slab.last)) writeXYVertices(slab, r);
      if (work_[r] & kZVertices) writeZVertices(slab, r);
      if (work_[r] & kTriangles) writeTriangles(r);
    }
  });
}

// Row r's x and y vertices.
void SlabMarcher::writeXYVertices(const Slab& slab, size_t r) {
  const int nx = grid_.n[0] + 1, ny = grid_.n[1] + 1;
  const int j = static_cast<int>(r % ny), k = slab.k0 + static_cast<int>(r / ny);
  const float* f = slab.values + r * nx;
  const uint64_t* a = &bits_[r * words_];
  const CellRow row = cellRow(r, false);
  EdgeVertex* out = &out_.vertices[xyVertex_[r]];
  for (int w = 0; w < row.realWords; ++w) {
    forEachBit(row.xEdges(a, w), w, [&](int i) {
      *out++ = {grid_.corner(i, j, k), grid_.corner(i + 1, j, k), f[i], f[i + 1]};
    });
  }
  if (j + 1 == ny) return;
  for (int w = 0; w < row.realWords; ++w) {
    forEachBit(a[w] ^ a[w + words_], w, [&](int i) {
      *out++ = {grid_.corner(i, j, k), grid_.corner(i, j + 1, k), f[i], f[i + nx]};
    });
  }
}

// Row r's z vertices (to the next layer).
void SlabMarcher::writeZVertices(const Slab& slab, size_t r) {
  const int nx = grid_.n[0] + 1, ny = grid_.n[1] + 1;
  const int j = static_cast<int>(r % ny), k = slab.k0 + static_cast<int>(r / ny);
  const float* f = slab.values + r * nx;
  const uint64_t* a = &bits_[r * words_];
  const size_t nextLayerBits = static_cast<size_t>(ny) * words_, nextLayer = size_t{1} * ny * nx;
  EdgeVertex* out = &out_.vertices[zVertex_[r]];
  for (int w = 0; w + 1 < words_; ++w) {
    forEachBit(a[w] ^ a[w + nextLayerBits], w, [&](int i) {
      *out++ = {grid_.corner(i, j, k), grid_.corner(i, j, k + 1), f[i], f[i + nextLayer]};
    });
  }
}

// The crossed edges of one axis that a row of corners owns: with its per-word ranks, the vertex
// of the edge at corner i is one popcount away.
struct SlabMarcher::EdgeRun {
  const uint64_t* row;
  const uint64_t* other;  // the row at the edges' other ends; null: the row's own x edges
  const uint16_t* rank;   // per word: the run's crossed edges before it
  uint32_t first;         // the run's first vertex

  uint32_t vertex(int i) const {
    const int w = i >> 6;
    const uint64_t crossed = other ? row[w] ^ other[w] : row[w] ^ nextCorners(row, w);
    return first + rank[w] + bitCount(crossed & bitsBelow(i & 63));
  }
};

// The triangles of the row of cells above row r (between rows j, j + 1 and layers k, k + 1).
void SlabMarcher::writeTriangles(size_t r) {
  const CellRow row = cellRow(r, true);
  const size_t ny = grid_.n[1] + 1, b = r + 1, c = r + ny, d = c + 1;
  const int words = row.realWords;
  auto ranks = [&](size_t of, int axis) { return &ranks_[(of * 3 + axis) * words]; };
  // In the order of CaseTable::mask: x edges of rows a, b, c, d; y edges of a, c; z of a, b.
  const EdgeRun runs[8] = {
      {row.a, nullptr, ranks(r, 0), xyVertex_[r]},
      {row.b, nullptr, ranks(b, 0), xyVertex_[b]},
      {row.c, nullptr, ranks(c, 0), xyVertex_[c]},
      {row.d, nullptr, ranks(d, 0), xyVertex_[d]},
      {row.a, row.b, ranks(r, 1), xyVertex_[r] + xVertices_[r]},
      {row.c, row.d, ranks(c, 1), xyVertex_[c] + xVertices_[c]},
      {row.a, row.c, ranks(r, 2), zVertex_[r]},
      {row.b, row.d, ranks(b, 2), zVertex_[b]},
  };
  const CaseTable& table = CaseTable::instance();
  uint32_t* out = &out_.indices[3 * static_cast<size_t>(triangle_[r])];
  for (int w = 0; w < words; ++w) {
    forEachBit(row.surfaceCells(w), w, [&](int i) {
      const int configuration = row.configuration(i);
      // Each crossed edge's vertex once, then the triangles from them.
      uint32_t vertex[12];
      for (uint32_t edges = table.crossed[configuration]; edges; edges &= edges - 1) {
        const int edge = __builtin_ctz(edges);
        vertex[edge] = runs[table.mask[edge]].vertex(i + table.dx[edge]);
      }
      for (int e = table.begin[configuration]; e < table.begin[configuration + 1]; ++e) {
        *out++ = vertex[table.edges[e]];
      }
    });
  }
}

}  // namespace limn::render::implicit
