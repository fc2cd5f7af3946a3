// locateOutline: see outline.h (compareOutlines is in outline_distances.cpp).
#include "render/metrics/outline.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>

namespace limn::render::metrics {

namespace {

// ---- Locating ----

// Interleaves the bits of two 32-bit numbers (x in the even bits).
uint64_t interleave(uint32_t x, uint32_t y) {
  auto spread = [](uint64_t v) {
    v = (v | (v << 16)) & 0x0000FFFF0000FFFFull;
    v = (v | (v << 8)) & 0x00FF00FF00FF00FFull;
    v = (v | (v << 4)) & 0x0F0F0F0F0F0F0F0Full;
    v = (v | (v << 2)) & 0x3333333333333333ull;
    return (v | (v << 1)) & 0x5555555555555555ull;
  };
  return spread(x) | (spread(y) << 1);
}

uint32_t compact(uint64_t v) {
  v &= 0x5555555555555555ull;
  v = (v | (v >> 1)) & 0x3333333333333333ull;
  v = (v | (v >> 2)) & 0x0F0F0F0F0F0F0F0Full;
  v = (v | (v >> 4)) & 0x00FF00FF00FF00FFull;
  v = (v | (v >> 8)) & 0x0000FFFF0000FFFFull;
  return static_cast<uint32_t>((v | (v >> 16)) & 0x00000000FFFFFFFFull);
}

// The sample grid of a supersampled mask: sample (i, j) sits at the centre of mask pixel (i, j).
// Samples are numbered in Morton order, so that sorted lists of samples, edges and crossings are
// spatially coherent: queries get neighbouring points together (cheaper ray packets).
struct SampleGrid {
  int width, height, supersample;

  Vec2 position(int i, int j) const { return {(i + 0.5) / supersample, (j + 0.5) / supersample}; }
  uint64_t sample(int i, int j) const {
    return interleave(static_cast<uint32_t>(i), static_cast<uint32_t>(j));
  }
  int column(uint64_t s) const { return static_cast<int>(compact(s)); }
  int row(uint64_t s) const { return static_cast<int>(compact(s >> 1)); }
  // Grid edges: horizontal from sample (i, j) to (i + 1, j), vertical from (i, j) to (i, j + 1).
  uint64_t horizontal(int i, int j) const { return 2 * sample(i, j); }
  uint64_t vertical(int i, int j) const { return 2 * sample(i, j) + 1; }
  void ends(uint64_t edge, Vec2* a, Vec2* b) const {
    uint64_t s = edge / 2;
    int i = column(s), j = row(s);
    *a = position(i, j);
    *b = (edge & 1) ? position(i, j + 1) : position(i + 1, j);
  }
};

// A sorted list of keys with a value each, looked up by binary search.
template <typename Value>
struct SortedMap {
  std::vector<uint64_t> keys;
  std::vector<Value> values;
  const Value* find(uint64_t key) const {
    auto it = std::lower_bound(keys.begin(), keys.end(), key);
    return it != keys.end() && *it == key ? &values[it - keys.begin()] : nullptr;
  }
};

void sortUnique(std::vector<uint64_t>& keys) {
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
}

// Cells (by their first sample) whose four mask samples are not all alike, in sample order.
// Runs of kRun cells whose two rows hold one value throughout are skipped after a branch-free
// comparison (most of a mask is uniform), the rest is looked at cell by cell.
std::vector<uint64_t> mixedCells(const Mask& mask, const SampleGrid& grid) {
  constexpr int kRun = 32;
  const int w = grid.width, h = grid.height;
  std::vector<std::vector<uint64_t>> perRow(std::max(0, h - 1));
  tbb::parallel_for(tbb::blocked_range<int>(0, h - 1, 8), [&](const tbb::blocked_range<int>& r) {
    std::vector<uint8_t> top(w), bottom(w);
    auto covered = [&](int j, std::vector<uint8_t>& out) {
      const uint8_t* row = mask.covered.data() + static_cast<size_t>(j) * w;
      for (int i = 0; i < w; ++i) out[i] = row[i] != 0;
    };
    covered(r.begin(), top);
    for (int j = r.begin(); j < r.end(); ++j) {
      covered(j + 1, bottom);
      for (int i0 = 0; i0 + 1 < w; i0 += kRun) {
        const int i1 = std::min(w - 1, i0 + kRun);  // cells i0 .. i1 - 1 use samples i0 .. i1
        uint8_t differ = 0;
        for (int i = i0; i <= i1; ++i) differ |= (top[i] ^ top[i0]) | (bottom[i] ^ top[i0]);
        if (!differ) continue;
        for (int i = i0; i < i1; ++i) {
          uint8_t a = top[i];
          if ((top[i + 1] ^ a) | (bottom[i] ^ a) | (bottom[i + 1] ^ a)) {
            perRow[j].push_back(grid.sample(i, j));
          }
        }
      }
      std::swap(top, bottom);
    }
  });
  std::vector<uint64_t> cells;
  for (auto& row : perRow) cells.insert(cells.end(), row.begin(), row.end());
  std::sort(cells.begin(), cells.end());
  return cells;
}

// The mixed cells in and along the blocks of the flagged output pixels: cells whose first
// sample lies in [x S - 1, x S + S - 1] x [y S - 1, y S + S - 1] for a flagged (x, y).
std::vector<uint64_t> mixedCellsIn(const Mask& mask, const SampleGrid& grid,
                                   const std::vector<char>& scan) {
  const int s = grid.supersample, outWidth = grid.width / s, outHeight = grid.height / s;
  auto covered = [&](int i, int j) { return mask.at(i, j) != 0; };
  std::vector<uint64_t> cells;
  for (int y = 0; y < outHeight; ++y) {
    for (int x = 0; x < outWidth; ++x) {
      if (!scan[static_cast<size_t>(y) * outWidth + x]) continue;
      for (int j = std::max(0, y * s - 1); j < std::min(grid.height - 1, y * s + s); ++j) {
        for (int i = std::max(0, x * s - 1); i < std::min(grid.width - 1, x * s + s); ++i) {
          bool a = covered(i, j);
          if (covered(i + 1, j) != a || covered(i, j + 1) != a || covered(i + 1, j + 1) != a) {
            cells.push_back(grid.sample(i, j));
          }
        }
      }
    }
  }
  sortUnique(cells);
  return cells;
}

// Coverage of the corners of every cell, by the query (not the mask: the two may disagree at a
// sample by rounding, and the crossings must bracket the query's own boundary).
SortedMap<char> cornerCoverage(const std::vector<uint64_t>& cells, const SampleGrid& grid,
                               const CoverageQuery& query) {
  SortedMap<char> corners;
  for (uint64_t c : cells) {
    int i = grid.column(c), j = grid.row(c);
    for (int dj = 0; dj < 2; ++dj) {
      for (int di = 0; di < 2; ++di) corners.keys.push_back(grid.sample(i + di, j + dj));
    }
  }
  sortUnique(corners.keys);
  std::vector<Vec2> points(corners.keys.size());
  for (size_t k = 0; k < points.size(); ++k) {
    points[k] = grid.position(grid.column(corners.keys[k]), grid.row(corners.keys[k]));
  }
  query(points, corners.values);
  return corners;
}

// The edges of the cells whose two ends the query sees differently.
std::vector<uint64_t> crossedEdges(const std::vector<uint64_t>& cells, const SampleGrid& grid,
                                   const SortedMap<char>& corners) {
  std::vector<uint64_t> edges;
  auto covered = [&](int i, int j) { return *corners.find(grid.sample(i, j)) != 0; };
  for (uint64_t c : cells) {
    int i = grid.column(c), j = grid.row(c);
    bool c00 = covered(i, j), c10 = covered(i + 1, j), c01 = covered(i, j + 1),
         c11 = covered(i + 1, j + 1);
    if (c00 != c10) edges.push_back(grid.horizontal(i, j));
    if (c01 != c11) edges.push_back(grid.horizontal(i, j + 1));
    if (c00 != c01) edges.push_back(grid.vertical(i, j));
    if (c10 != c11) edges.push_back(grid.vertical(i + 1, j));
  }
  sortUnique(edges);
  return edges;
}

// Bisects every bracket [inside, outside] at once (one query batch per halving) until it is
// shorter than `tolerance`; the crossing is the bracket's middle.
std::vector<Vec2> bisect(std::vector<Vec2> in, std::vector<Vec2> out, double length,
                         const CoverageQuery& query, const CancelToken& cancel, double tolerance) {
  const int steps = static_cast<int>(std::ceil(std::log2(length / tolerance)));
  std::vector<Vec2> middles(in.size());
  std::vector<char> covered;
  for (int step = 0; step < steps && !in.empty(); ++step) {
    cancel.check();
    for (size_t k = 0; k < in.size(); ++k) {
      middles[k] = {(in[k].x + out[k].x) / 2, (in[k].y + out[k].y) / 2};
    }
    query(middles, covered);
    for (size_t k = 0; k < in.size(); ++k) (covered[k] ? in[k] : out[k]) = middles[k];
  }
  for (size_t k = 0; k < in.size(); ++k) {
    middles[k] = {(in[k].x + out[k].x) / 2, (in[k].y + out[k].y) / 2};
  }
  return middles;
}

// The crossing on every crossed grid edge.
std::vector<Vec2> bisectEdges(const std::vector<uint64_t>& edges, const SampleGrid& grid,
                              const SortedMap<char>& corners, const CoverageQuery& query,
                              const CancelToken& cancel, double tolerance) {
  std::vector<Vec2> in(edges.size()), out(edges.size());  // covered end, uncovered end
  for (size_t k = 0; k < edges.size(); ++k) {
    Vec2 a, b;
    grid.ends(edges[k], &a, &b);
    bool aCovered = *corners.find(grid.sample(grid.column(edges[k] / 2), grid.row(edges[k] / 2)));
    in[k] = aCovered ? a : b;
    out[k] = aCovered ? b : a;
  }
  return bisect(std::move(in), std::move(out), 1.0 / grid.supersample, query, cancel, tolerance);
}

// Segments next to a point where the polyline turns by more than kSharpTurnDeg, or that end at a
// point not joined to exactly two segments. On a smooth outline the polyline turns by about
// (cell / radius of curvature) per point, a few degrees, and its chords are already within
// cell^2 / (8 radius) of the curve (under 1e-3 px at S = 4 for radii over 8 px).
std::vector<size_t> segmentsAtSharpTurns(const Outline& outline) {
  constexpr double kSharpTurnDeg = 15;
  const double cosSharp = std::cos(kSharpTurnDeg * 3.14159265358979323846 / 180);
  const size_t n = outline.segments.size();
  std::vector<std::array<int, 2>> incident(outline.points.size(), {-1, -1});
  std::vector<int> degree(outline.points.size(), 0);
  for (size_t k = 0; k < n; ++k) {
    for (int end : {outline.segments[k].first, outline.segments[k].second}) {
      if (degree[end] < 2) incident[end][degree[end]] = static_cast<int>(k);
      ++degree[end];
    }
  }
  std::vector<char> sharp(n, 0);
  for (size_t p = 0; p < outline.points.size(); ++p) {
    if (degree[p] == 0) continue;
    bool turns = degree[p] != 2;
    if (!turns) {
      auto other = [&](int segment) {
        const auto& s = outline.segments[segment];
        return outline.points[s.first == static_cast<int>(p) ? s.second : s.first];
      };
      Vec2 here = outline.points[p], a = other(incident[p][0]), b = other(incident[p][1]);
      double ax = here.x - a.x, ay = here.y - a.y, bx = b.x - here.x, by = b.y - here.y;
      double la = std::hypot(ax, ay), lb = std::hypot(bx, by);
      turns = la > 0 && lb > 0 && (ax * bx + ay * by) < cosSharp * la * lb;
    }
    if (!turns) continue;
    for (int segment : incident[p]) {
      if (segment >= 0) sharp[segment] = 1;
    }
  }
  std::vector<size_t> which;
  for (size_t k = 0; k < n; ++k) {
    if (sharp[k]) which.push_back(k);
  }
  return which;
}

// Moves the middle of every segment at a sharp turn onto the outline: a search along the
// chord's perpendicular, half a cell either way, splits the segment in two at the crossing
// found (a segment whose perpendicular sees one coverage at both ends stays whole). This puts a
// point on a sharp corner that falls inside a cell, which a chord between two cell edges would
// cut by up to 0.09 cell.
void splitSegments(Outline& outline, double cell, const CoverageQuery& query,
                   const CancelToken& cancel, double tolerance) {
  const std::vector<size_t> candidates = segmentsAtSharpTurns(outline);
  const size_t n = candidates.size();
  std::vector<Vec2> ends(2 * n);
  for (size_t c = 0; c < n; ++c) {
    const size_t k = candidates[c];
    Vec2 a = outline.points[outline.segments[k].first];
    Vec2 b = outline.points[outline.segments[k].second];
    double dx = b.x - a.x, dy = b.y - a.y, len = std::hypot(dx, dy);
    Vec2 m{(a.x + b.x) / 2, (a.y + b.y) / 2};
    Vec2 normal = len > 0 ? Vec2{-dy / len, dx / len} : Vec2{0, 0};
    ends[2 * c] = {m.x - normal.x * cell / 2, m.y - normal.y * cell / 2};
    ends[2 * c + 1] = {m.x + normal.x * cell / 2, m.y + normal.y * cell / 2};
  }
  std::vector<char> covered;
  query(ends, covered);
  std::vector<Vec2> in, out;
  std::vector<size_t> which;
  for (size_t c = 0; c < n; ++c) {
    if (covered[2 * c] == covered[2 * c + 1]) continue;
    in.push_back(ends[2 * c + (covered[2 * c] ? 0 : 1)]);
    out.push_back(ends[2 * c + (covered[2 * c] ? 1 : 0)]);
    which.push_back(candidates[c]);
  }
  std::vector<Vec2> middles = bisect(std::move(in), std::move(out), cell, query, cancel, tolerance);
  outline.segments.reserve(outline.segments.size() + which.size());
  for (size_t i = 0; i < which.size(); ++i) {
    const int middle = static_cast<int>(outline.points.size());
    outline.points.push_back(middles[i]);
    const int end = outline.segments[which[i]].second;
    outline.segments[which[i]].second = middle;
    outline.segments.emplace_back(middle, end);
  }
}

// Joins the crossings of each cell as marching squares does. A cell crossed on all four edges
// (a saddle) is resolved by the query at its centre: when the centre is covered like the corners
// (i, j) and (i + 1, j + 1), those two are connected through it and the segments cut off the
// other two corners.
std::vector<std::pair<int, int>> joinCells(const std::vector<uint64_t>& cells,
                                           const SampleGrid& grid, const SortedMap<char>& corners,
                                           const std::vector<uint64_t>& edges,
                                           const CoverageQuery& query) {
  auto crossing = [&](uint64_t edge) {
    auto it = std::lower_bound(edges.begin(), edges.end(), edge);
    return it != edges.end() && *it == edge ? static_cast<int>(it - edges.begin()) : -1;
  };
  std::vector<std::pair<int, int>> segments;
  std::vector<uint64_t> saddles;
  for (uint64_t c : cells) {
    int i = grid.column(c), j = grid.row(c);
    // Around the cell: top, right, bottom, left.
    int e[4] = {crossing(grid.horizontal(i, j)), crossing(grid.vertical(i + 1, j)),
                crossing(grid.horizontal(i, j + 1)), crossing(grid.vertical(i, j))};
    int found[4], n = 0;
    for (int k : e) {
      if (k >= 0) found[n++] = k;
    }
    if (n == 2) segments.emplace_back(found[0], found[1]);
    if (n == 4) saddles.push_back(c);
  }
  if (saddles.empty()) return segments;
  std::vector<Vec2> centres(saddles.size());
  for (size_t k = 0; k < saddles.size(); ++k) {
    Vec2 p = grid.position(grid.column(saddles[k]), grid.row(saddles[k]));
    centres[k] = {p.x + 0.5 / grid.supersample, p.y + 0.5 / grid.supersample};
  }
  std::vector<char> centreCovered;
  query(centres, centreCovered);
  for (size_t k = 0; k < saddles.size(); ++k) {
    int i = grid.column(saddles[k]), j = grid.row(saddles[k]);
    int top = crossing(grid.horizontal(i, j)), right = crossing(grid.vertical(i + 1, j)),
        bottom = crossing(grid.horizontal(i, j + 1)), left = crossing(grid.vertical(i, j));
    bool diagonalJoined = (centreCovered[k] != 0) == (*corners.find(grid.sample(i, j)) != 0);
    if (diagonalJoined) {  // cut off corners (i + 1, j) and (i, j + 1)
      segments.emplace_back(top, right);
      segments.emplace_back(bottom, left);
    } else {  // cut off corners (i, j) and (i + 1, j + 1)
      segments.emplace_back(top, left);
      segments.emplace_back(right, bottom);
    }
  }
  return segments;
}

}  // namespace

Outline locateOutline(const Mask& mask, int supersample, const CoverageQuery& query,
                      const CancelToken& cancel, const std::vector<char>* scan,
                      double tolerancePx) {
  if (supersample < 1) throw std::invalid_argument("locateOutline: a supersample >= 1");
  SampleGrid grid{mask.width, mask.height, supersample};
  const size_t outputPixels =
      static_cast<size_t>(mask.width / supersample) * (mask.height / supersample);
  std::vector<uint64_t> cells = scan && scan->size() == outputPixels
                                    ? mixedCellsIn(mask, grid, *scan)
                                    : mixedCells(mask, grid);
  cancel.check();
  Outline outline;
  outline.frameWidth = static_cast<double>(mask.width) / supersample;
  outline.frameHeight = static_cast<double>(mask.height) / supersample;
  if (cells.empty()) return outline;
  SortedMap<char> corners = cornerCoverage(cells, grid, query);
  std::vector<uint64_t> edges = crossedEdges(cells, grid, corners);
  outline.points = bisectEdges(edges, grid, corners, query, cancel, tolerancePx);
  outline.segments = joinCells(cells, grid, corners, edges, query);
  splitSegments(outline, 1.0 / supersample, query, cancel, tolerancePx);
  return outline;
}

}  // namespace limn::render::metrics
