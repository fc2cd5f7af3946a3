// Small control meshes made by code, shared by unit tests and benchmarks.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <iterator>
#include <map>
#include <numbers>
#include <vector>

#include "render/mesh/control_mesh.h"

namespace limn::testing {

using render::Vec3;
using render::mesh::ControlMesh;
using render::mesh::Scheme;

inline void addFace(ControlMesh& m, std::initializer_list<int> vertices) {
  m.faceVertexCounts.push_back(static_cast<int>(vertices.size()));
  m.faceVertexIndices.insert(m.faceVertexIndices.end(), vertices);
}

// Unit cube centred at the origin, faces wound counter-clockwise seen from outside.
inline ControlMesh cube(Scheme scheme = Scheme::CatmullClark) {
  ControlMesh m;
  m.scheme = scheme;
  m.points = {{-0.5, -0.5, 0.5}, {0.5, -0.5, 0.5}, {-0.5, 0.5, 0.5},   {0.5, 0.5, 0.5},
              {-0.5, 0.5, -0.5}, {0.5, 0.5, -0.5}, {-0.5, -0.5, -0.5}, {0.5, -0.5, -0.5}};
  addFace(m, {0, 1, 3, 2});
  addFace(m, {2, 3, 5, 4});
  addFace(m, {4, 5, 7, 6});
  addFace(m, {6, 7, 1, 0});
  addFace(m, {1, 7, 5, 3});
  addFace(m, {6, 0, 2, 4});
  return m;
}

inline ControlMesh tetrahedron(Scheme scheme = Scheme::Loop) {
  ControlMesh m;
  m.scheme = scheme;
  m.points = {{1, 1, 1}, {-1, -1, 1}, {-1, 1, -1}, {1, -1, -1}};
  addFace(m, {0, 1, 3});
  addFace(m, {0, 2, 1});
  addFace(m, {0, 3, 2});
  addFace(m, {1, 2, 3});
  return m;
}

inline ControlMesh octahedron(Scheme scheme = Scheme::CatmullClark) {
  ControlMesh m;
  m.scheme = scheme;
  m.points = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  addFace(m, {0, 2, 4});
  addFace(m, {2, 1, 4});
  addFace(m, {1, 3, 4});
  addFace(m, {3, 0, 4});
  addFace(m, {2, 0, 5});
  addFace(m, {1, 2, 5});
  addFace(m, {3, 1, 5});
  addFace(m, {0, 3, 5});
  return m;
}

inline ControlMesh icosahedron(Scheme scheme = Scheme::Loop) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  ControlMesh m;
  m.scheme = scheme;
  m.points = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
              {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  const int faces[20][3] = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                            {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                            {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                            {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (const auto& f : faces) addFace(m, {f[0], f[1], f[2]});
  return m;
}

// Open grid of n x n quads in the xy plane with a height field, boundary edge-only.
inline ControlMesh grid(int n, double amplitude = 0.2) {
  ControlMesh m;
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) {
      double x = static_cast<double>(i) / n - 0.5, y = static_cast<double>(j) / n - 0.5;
      m.points.push_back({x, y, amplitude * std::sin(3.0 * x + 1.0) * std::cos(2.0 * y)});
    }
  }
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      int a = j * (n + 1) + i;
      addFace(m, {a, a + 1, a + n + 2, a + n + 1});
    }
  }
  return m;
}

// Torus of `ring` x `tube` quads; with creases, one ring of edges is infinitely sharp and one
// tube loop semi-sharp (2.0).
inline ControlMesh torus(int ring = 12, int tube = 8, bool creases = true) {
  ControlMesh m;
  const double R = 1.0, r = 0.35;
  for (int i = 0; i < ring; ++i) {
    double a = 2 * std::numbers::pi * i / ring;
    for (int j = 0; j < tube; ++j) {
      double b = 2 * std::numbers::pi * j / tube;
      m.points.push_back({(R + r * std::cos(b)) * std::cos(a), (R + r * std::cos(b)) * std::sin(a),
                          r * std::sin(b)});
    }
  }
  auto id = [&](int i, int j) { return (i % ring) * tube + (j % tube); };
  for (int i = 0; i < ring; ++i) {
    for (int j = 0; j < tube; ++j)
      addFace(m, {id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
  }
  if (creases) {
    for (int i = 0; i < ring; ++i) m.creases.push_back({id(i, 0), id(i + 1, 0), 10.0f});
    for (int j = 0; j < tube; ++j) m.creases.push_back({id(0, j), id(0, j + 1), 2.0f});
  }
  return m;
}

// Merges coincident points (within 1e-9) and renumbers the faces: for meshes made of patches
// whose shared borders were generated twice.
inline ControlMesh weldPoints(ControlMesh m) {
  std::vector<int> remap(m.points.size());
  std::vector<Vec3> kept;
  for (size_t i = 0; i < m.points.size(); ++i) {
    int found = -1;
    for (size_t j = 0; j < kept.size() && found < 0; ++j) {
      Vec3 d = kept[j] - m.points[i];
      if (d.x * d.x + d.y * d.y + d.z * d.z < 1e-18) found = static_cast<int>(j);
    }
    if (found < 0) {
      found = static_cast<int>(kept.size());
      kept.push_back(m.points[i]);
    }
    remap[i] = found;
  }
  for (int& v : m.faceVertexIndices) v = remap[v];
  m.points = std::move(kept);
  return m;
}

// A bumpy ball: a cube whose faces are split into n x n quads, pushed onto a sphere and
// displaced by a few low-frequency bumps. 6 n^2 faces (n = 16: 1,536), eight valence-3 vertices,
// the rest regular: a dense closed model with inner contours from most views.
inline ControlMesh bumpyBall(int n = 16) {
  ControlMesh m;
  auto id = [n](int side, int i, int j) { return (side * (n + 1) + j) * (n + 1) + i; };
  // Each side: origin corner and two axes spanning it, wound outwards.
  const Vec3 frames[6][3] = {
      {{-1, -1, 1}, {2, 0, 0}, {0, 2, 0}}, {{1, -1, -1}, {-2, 0, 0}, {0, 2, 0}},
      {{1, -1, 1}, {0, 0, -2}, {0, 2, 0}}, {{-1, -1, -1}, {0, 0, 2}, {0, 2, 0}},
      {{-1, 1, 1}, {2, 0, 0}, {0, 0, -2}}, {{-1, -1, -1}, {2, 0, 0}, {0, 0, 2}}};
  for (int side = 0; side < 6; ++side) {
    for (int j = 0; j <= n; ++j) {
      for (int i = 0; i <= n; ++i) {
        const Vec3* f = frames[side];
        Vec3 c = f[0] + f[1] * (static_cast<double>(i) / n) + f[2] * (static_cast<double>(j) / n);
        Vec3 d = c * (1.0 / std::sqrt(c.x * c.x + c.y * c.y + c.z * c.z));
        double bump = 1.0 + 0.12 * std::sin(3 * d.x + 1) * std::sin(4 * d.y) * std::cos(2 * d.z) +
                      0.06 * std::sin(7 * d.z + 2 * d.x);
        m.points.push_back(d * bump);
      }
    }
  }
  for (int side = 0; side < 6; ++side) {
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        addFace(m,
                {id(side, i, j), id(side, i + 1, j), id(side, i + 1, j + 1), id(side, i, j + 1)});
      }
    }
  }
  return weldPoints(m);
}

// A chess pawn as a surface of revolution: `around` x `rows` faces (28 x 21 = 588), quads with a
// triangle fan closing each pole (poles of valence `around`).
inline ControlMesh pawn(int around = 28) {
  // Profile (radius, height) from the bottom pole to the top pole.
  const double profile[][2] = {{0.0, 0.0},   {0.55, 0.0},  {0.6, 0.06},  {0.58, 0.14}, {0.45, 0.2},
                               {0.4, 0.28},  {0.36, 0.38}, {0.3, 0.52},  {0.25, 0.68}, {0.22, 0.82},
                               {0.34, 0.88}, {0.36, 0.93}, {0.24, 0.97}, {0.2, 1.02},  {0.26, 1.1},
                               {0.32, 1.2},  {0.33, 1.3},  {0.3, 1.4},   {0.22, 1.48}, {0.12, 1.53},
                               {0.0, 1.55}};
  const int rings = static_cast<int>(std::size(profile)) - 2;  // without the two poles
  ControlMesh m;
  m.points.push_back({0, profile[0][1], 0});
  for (int r = 1; r <= rings; ++r) {
    for (int k = 0; k < around; ++k) {
      double a = 2 * std::numbers::pi * k / around;
      m.points.push_back(
          {profile[r][0] * std::cos(a), profile[r][1], -profile[r][0] * std::sin(a)});
    }
  }
  const int top = static_cast<int>(m.points.size());
  m.points.push_back({0, profile[rings + 1][1], 0});
  auto id = [around](int r, int k) { return 1 + (r - 1) * around + (k % around); };
  for (int k = 0; k < around; ++k) addFace(m, {0, id(1, k + 1), id(1, k)});
  for (int r = 1; r < rings; ++r) {
    for (int k = 0; k < around; ++k)
      addFace(m, {id(r, k), id(r, k + 1), id(r + 1, k + 1), id(r + 1, k)});
  }
  for (int k = 0; k < around; ++k) addFace(m, {id(rings, k), id(rings, k + 1), top});
  return m;
}

// Creases on every edge of `m` (sharpness per edge from `sharpness(edge index)`), for the
// sharp-feature meshes below. Edges are listed once, in the order faces first use them.
template <class Sharpness>
inline ControlMesh withEveryEdgeCreased(ControlMesh m, Sharpness sharpness) {
  std::vector<std::pair<int, int>> seen;
  size_t offset = 0;
  for (int count : m.faceVertexCounts) {
    for (int k = 0; k < count; ++k) {
      int a = m.faceVertexIndices[offset + k], b = m.faceVertexIndices[offset + (k + 1) % count];
      std::pair<int, int> key{std::min(a, b), std::max(a, b)};
      bool known = false;
      for (const auto& e : seen) known = known || e == key;
      if (known) continue;
      seen.push_back(key);
      m.creases.push_back({a, b, sharpness(static_cast<int>(seen.size()) - 1)});
    }
    offset += count;
  }
  return m;
}

// The project's sharp-feature meshes (issue 10): a cube whose edges and corners are all
// infinitely sharp (its limit surface is the cube itself, every contour an outline along sharp
// edges), one with only its corners infinitely sharp (smooth faces meeting in eight points), a
// semi-sharp cube (sharpness 1 to 3 by edge) and the same with Chaikin's crease rule, and Loop's
// tetrahedron with infinitely sharp edges.
inline ControlMesh sharpCube(Scheme scheme = Scheme::CatmullClark) {
  ControlMesh m =
      withEveryEdgeCreased(cube(scheme), [](int) { return render::mesh::kInfiniteSharpness; });
  for (int v = 0; v < 8; ++v) m.corners.push_back({v, render::mesh::kInfiniteSharpness});
  return m;
}
inline ControlMesh cubeWithSharpCorners(Scheme scheme = Scheme::CatmullClark) {
  ControlMesh m = cube(scheme);
  for (int v = 0; v < 8; ++v) m.corners.push_back({v, render::mesh::kInfiniteSharpness});
  return m;
}
inline ControlMesh semiSharpCube(bool chaikin = false) {
  ControlMesh m = withEveryEdgeCreased(cube(), [](int e) { return 1.0f + (e % 3); });
  if (chaikin) m.creaseMethod = render::mesh::CreaseMethod::Chaikin;
  return m;
}
inline ControlMesh sharpTetrahedron() {
  return withEveryEdgeCreased(
      tetrahedron(), [](int e) { return e % 2 == 0 ? render::mesh::kInfiniteSharpness : 2.0f; });
}

// A dense torus for the triangle-share measurements (issue 10): `ring` x `tube` quads
// (48 x 24 = 1,152) with every vertex pushed along its normal by a few smooth waves, so the
// contour wanders over the faces rather than following the grid.
inline ControlMesh wavyTorus(int ring = 48, int tube = 24) {
  ControlMesh m = torus(ring, tube, false);
  const double R = 1.0;
  for (int i = 0; i < ring; ++i) {
    double a = 2 * std::numbers::pi * i / ring;
    for (int j = 0; j < tube; ++j) {
      double b = 2 * std::numbers::pi * j / tube;
      Vec3& p = m.points[i * tube + j];
      Vec3 centre{R * std::cos(a), R * std::sin(a), 0};
      Vec3 out = p - centre;
      double wave = 1.0 + 0.18 * std::sin(5 * a + 2 * b) + 0.08 * std::cos(9 * a - b);
      p = centre + out * wave;
    }
  }
  return m;
}

// An icosphere: the icosahedron with every triangle split into four `levels` times, the new
// points pushed onto the unit sphere and then out by a few smooth bumps. 20 * 4^levels
// triangles (3: 1,280). As a Catmull-Clark mesh every face is a triangle (no quad at all) and
// every vertex extraordinary: the hardest dense input for methods that want quads.
inline ControlMesh icosphere(int levels = 3, Scheme scheme = Scheme::CatmullClark) {
  ControlMesh m = icosahedron(scheme);
  for (Vec3& p : m.points) p = p * (1.0 / std::sqrt(p.x * p.x + p.y * p.y + p.z * p.z));
  for (int level = 0; level < levels; ++level) {
    std::vector<std::pair<std::pair<int, int>, int>> midpoints;
    auto midpoint = [&](int a, int b) {
      std::pair<int, int> key{std::min(a, b), std::max(a, b)};
      for (const auto& [k, v] : midpoints) {
        if (k == key) return v;
      }
      Vec3 p = (m.points[a] + m.points[b]) * 0.5;
      m.points.push_back(p * (1.0 / std::sqrt(p.x * p.x + p.y * p.y + p.z * p.z)));
      midpoints.push_back({key, static_cast<int>(m.points.size()) - 1});
      return midpoints.back().second;
    };
    std::vector<int> old = m.faceVertexIndices;
    m.faceVertexIndices.clear();
    m.faceVertexCounts.clear();
    for (size_t i = 0; i < old.size(); i += 3) {
      int a = old[i], b = old[i + 1], c = old[i + 2];
      int ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
      addFace(m, {a, ab, ca});
      addFace(m, {ab, b, bc});
      addFace(m, {ca, bc, c});
      addFace(m, {ab, bc, ca});
    }
  }
  for (Vec3& p : m.points) {
    p = p * (1.0 + 0.15 * std::sin(4 * p.x + 1) * std::cos(3 * p.y) + 0.07 * std::sin(6 * p.z));
  }
  return m;
}

// The n x n grid (n >= 2) with its middle quad split in two through an extra vertex lifted
// above it: that vertex is interior with valence 2 (as in the corpus's catmark_val2_interior).
// The two split faces are the last two faces; the extra vertex is the last point.
inline ControlMesh gridWithValenceTwoVertex(int n = 4, double amplitude = 0.2) {
  ControlMesh m = grid(n, amplitude);
  const int split = (n / 2) * n + n / 2;
  const int* q = &m.faceVertexIndices[4 * split];
  const int a = q[0], b = q[1], c = q[2], d = q[3];
  Vec3 middle = (m.points[a] + m.points[b] + m.points[c] + m.points[d]) * 0.25;
  m.points.push_back(middle + Vec3{0.05, -0.03, 0.3});
  const int x = static_cast<int>(m.points.size()) - 1;
  m.faceVertexIndices.erase(m.faceVertexIndices.begin() + 4 * split,
                            m.faceVertexIndices.begin() + 4 * split + 4);
  m.faceVertexCounts.pop_back();
  addFace(m, {a, b, c, x});
  addFace(m, {a, x, c, d});
  return m;
}

// A smooth, non-symmetric displacement, so that no weight can hide behind a symmetry.
inline ControlMesh displaced(ControlMesh m, double amount = 0.08) {
  for (Vec3& p : m.points) {
    p += Vec3{std::sin(3 * p.y + 1), std::cos(2 * p.z + 0.5), std::sin(4 * p.x + 2 * p.y)} * amount;
  }
  return m;
}

// One topological split: Catmull-Clark's (every face into quads around its centre) or Loop's
// (every triangle into four), points at averages. A face of n sides becomes a vertex of
// valence n.
inline ControlMesh splitOnce(const ControlMesh& m) {
  ControlMesh out;
  out.scheme = m.scheme;
  out.points = m.points;
  std::map<std::pair<int, int>, int> midpoints;
  auto midpoint = [&](int a, int b) {
    auto [it, inserted] = midpoints.try_emplace({std::min(a, b), std::max(a, b)}, 0);
    if (inserted) {
      it->second = static_cast<int>(out.points.size());
      out.points.push_back((m.points[a] + m.points[b]) * 0.5);
    }
    return it->second;
  };
  size_t offset = 0;
  for (int size : m.faceVertexCounts) {
    const int* v = &m.faceVertexIndices[offset];
    offset += size;
    if (m.scheme == Scheme::Loop) {
      int ab = midpoint(v[0], v[1]), bc = midpoint(v[1], v[2]), ca = midpoint(v[2], v[0]);
      addFace(out, {v[0], ab, ca});
      addFace(out, {ab, v[1], bc});
      addFace(out, {ca, bc, v[2]});
      addFace(out, {ab, bc, ca});
      continue;
    }
    Vec3 centre;
    for (int k = 0; k < size; ++k) centre += m.points[v[k]] * (1.0 / size);
    const int c = static_cast<int>(out.points.size());
    out.points.push_back(centre);
    for (int k = 0; k < size; ++k) {
      addFace(out, {v[k], midpoint(v[k], v[(k + 1) % size]), c,
                    midpoint(v[(k + size - 1) % size], v[k])});
    }
  }
  return out;
}

// An n-sided prism (its caps are n-gons).
inline ControlMesh prism(int n) {
  ControlMesh m;
  for (int k = 0; k < n; ++k) {
    double a = 2 * std::numbers::pi * k / n;
    m.points.push_back({std::cos(a), std::sin(a), -0.6});
    m.points.push_back({std::cos(a), std::sin(a), 0.6});
  }
  for (int k = 0; k < n; ++k) {
    int next = (k + 1) % n;
    addFace(m, {2 * k, 2 * next, 2 * next + 1, 2 * k + 1});
  }
  std::vector<int> bottom, top;
  for (int k = 0; k < n; ++k) {
    bottom.push_back(2 * (n - 1 - k));
    top.push_back(2 * k + 1);
  }
  m.faceVertexCounts.push_back(n);
  m.faceVertexIndices.insert(m.faceVertexIndices.end(), bottom.begin(), bottom.end());
  m.faceVertexCounts.push_back(n);
  m.faceVertexIndices.insert(m.faceVertexIndices.end(), top.begin(), top.end());
  return m;
}

// An n-sided prism, split once: its two cap centres have valence n, its corners 3 (edge tables
// of every valence, issue 10).
inline ControlMesh splitPrism(int n) { return displaced(splitOnce(prism(n))); }

// An n-sided bipyramid of triangles (Loop), split once: its apices have valence n.
inline ControlMesh splitBipyramid(int n) {
  ControlMesh m;
  m.scheme = Scheme::Loop;
  for (int k = 0; k < n; ++k) {
    double a = 2 * std::numbers::pi * k / n;
    m.points.push_back({std::cos(a), std::sin(a), 0});
  }
  m.points.push_back({0, 0, 1.2});
  m.points.push_back({0, 0, -1.2});
  for (int k = 0; k < n; ++k) {
    int next = (k + 1) % n;
    addFace(m, {k, next, n});
    addFace(m, {next, k, n + 1});
  }
  return displaced(splitOnce(m));
}

// A creature-like closed-and-open Catmull-Clark cage of about 6 n^2 faces, standing in for the
// character models users bring: a cube-sphere of n x n quads per side (eight valence-3 poles)
// blown up into a bumpy, elongated body; an open mouth (a hole cut through, so a boundary
// loop); a band of triangles next to quads; an infinitely sharp ridge and a semi-sharp one.
inline ControlMesh creature(int n) {
  ControlMesh m;
  std::map<std::array<int, 3>, int> index;  // lattice point on the cube's surface -> vertex
  auto vertex = [&](std::array<int, 3> c) {
    auto [it, added] = index.try_emplace(c, static_cast<int>(m.points.size()));
    if (added) {
      Vec3 p{2.0 * c[0] / n - 1, 2.0 * c[1] / n - 1, 2.0 * c[2] / n - 1};
      const double len = std::sqrt(p.x * p.x + p.y * p.y + p.z * p.z);
      p = p / len;
      const double bump =
          1 + 0.08 * std::sin(5 * p.x) * std::sin(4 * p.y) + 0.05 * std::cos(7 * p.z);
      m.points.push_back({0.8 * bump * p.x, 1.4 * bump * p.y, 0.9 * bump * p.z});
    }
    return it->second;
  };
  // Each side: the axis it faces, its sign, and two in-plane axes whose cross product is its
  // outward normal (so the quads run counter-clockwise seen from outside).
  struct Side {
    int axis, u, v;
    bool high;
  };
  const Side sides[6] = {{0, 1, 2, true},  {0, 2, 1, false}, {1, 2, 0, true},
                         {1, 0, 2, false}, {2, 0, 1, true},  {2, 1, 0, false}};
  std::vector<std::array<int, 2>> ridge, semiRidge;
  for (int s = 0; s < 6; ++s) {
    const Side& side = sides[s];
    auto at = [&](int i, int j) {
      std::array<int, 3> c{};
      c[side.axis] = side.high ? n : 0;
      c[side.u] = i;
      c[side.v] = j;
      return vertex(c);
    };
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j < n; ++j) {
        const bool mouth = s == 4 && i >= n / 3 && i < 2 * n / 3 && j >= n / 5 && j < n / 3;
        if (mouth) continue;
        const int a = at(i, j), b = at(i + 1, j), c = at(i + 1, j + 1), d = at(i, j + 1);
        if (s == 2 && j >= n / 2 && j < n / 2 + n / 8) {  // the band of triangles
          addFace(m, {a, b, c});
          addFace(m, {a, c, d});
        } else {
          addFace(m, {a, b, c, d});
        }
        if (j == n / 2 && s == 1) ridge.push_back({a, b});
        if (j == n / 2 && s == 0) semiRidge.push_back({a, b});
      }
    }
  }
  for (auto [a, b] : ridge) m.creases.push_back({a, b, 10.0f});
  for (auto [a, b] : semiRidge) m.creases.push_back({a, b, 2.0f});
  return m;
}

// creature(n) for Loop's scheme: every face fanned into triangles from its first corner (so a
// quad's diagonal runs from its first corner; the creases are edges of both), which leaves
// vertices of valence 4 to 8 and the cube's poles at 3 to 6, like a triangulated scan.
inline ControlMesh loopCreature(int n) {
  const ControlMesh quads = creature(n);
  ControlMesh m = quads;
  m.scheme = Scheme::Loop;
  m.faceVertexCounts.clear();
  m.faceVertexIndices.clear();
  for (int f = 0, first = 0; f < quads.faceCount(); first += quads.faceVertexCounts[f++]) {
    const int* corner = quads.faceVertexIndices.data() + first;
    for (int k = 1; k + 1 < quads.faceVertexCounts[f]; ++k) {
      addFace(m, {corner[0], corner[k], corner[k + 1]});
    }
  }
  return m;
}

}  // namespace limn::testing
