#include "tests/support/mesh_generator.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <functional>
#include <set>
#include <utility>

#include "formats/obj_reader.h"

namespace limn::testing {

using render::Vec3;
using namespace render::mesh;

// ---------------------------------------------------------------------------------------------
// Choice sources

int ChoiceSource::range(int lo, int hi) {
  if (hi <= lo) return lo;
  const uint64_t span = static_cast<uint64_t>(static_cast<int64_t>(hi) - lo);
  return lo + static_cast<int>(bits(std::bit_width(span)) % (span + 1));
}

double ChoiceSource::logUniform(double lo, double hi) {
  return lo * std::exp(std::log(hi / lo) * unit());
}

uint64_t SeededChoices::bits(int n) { return rng_() >> (64 - n); }

// From the raw bits: std::uniform_real_distribution is not specified bit for bit, and a mesh
// must be the same for a seed on every standard library.
double SeededChoices::unit() { return static_cast<double>(rng_() >> 11) * 0x1.0p-53; }

uint64_t FuzzChoices::bits(int n) {
  uint64_t value = 0;
  for (int got = 0; got < n && pos_ < size_; got += 8) value = (value << 8) | data_[pos_++];
  return n >= 64 ? value : value & ((uint64_t{1} << n) - 1);
}

double FuzzChoices::unit() { return static_cast<double>(bits(16)) / 65536.0; }

namespace {

// ---------------------------------------------------------------------------------------------
// Building: pieces are made in a local frame of about unit size, placed by a random frame, and
// added face by face within the face budget and the valence limit.

struct Frame {
  Vec3 origin{0, 0, 0};
  Vec3 axes[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  Vec3 place(const Vec3& p) const { return origin + axes[0] * p.x + axes[1] * p.y + axes[2] * p.z; }
};

Vec3 rotate(const Vec3& v, const Vec3& axis, double angle) {  // Rodrigues
  const double c = std::cos(angle), s = std::sin(angle);
  return v * c + cross(axis, v) * s + axis * (dot(axis, v) * (1 - c));
}

Vec3 unitVector(ChoiceSource& c) {
  const double z = c.uniform(-1, 1), a = c.uniform(0, 2 * M_PI);
  const double r = std::sqrt(std::max(0.0, 1 - z * z));
  return {r * std::cos(a), r * std::sin(a), z};
}

class Builder {
 public:
  Builder(Scheme scheme, const GeneratorOptions& options) : scheme_(scheme), options_(options) {}

  // A random placement for the next piece: mostly within a few units of the origin at a scale
  // of 0.1-1.5; now and then tiny, far away, or flattened onto a plane, a line or a point
  // (every face of the piece then has zero area).
  void newPiece(ChoiceSource& c, std::string& description) {
    ++piece_;
    Frame f;
    f.origin = {c.uniform(-2, 2), c.uniform(-2, 2), c.uniform(-2, 2)};
    double scale = c.logUniform(0.1, 1.5);
    if (c.percent(4)) {
      scale = c.logUniform(1e-7, 1e-3);
      description += "[tiny]";
    } else if (c.percent(3)) {
      const Vec3 direction = unitVector(c);
      f.origin = direction * c.logUniform(1e2, 1e5);
      description += "[far]";
    }
    const Vec3 axis = unitVector(c);
    const double angle = c.uniform(0, 2 * M_PI);
    for (int i = 0; i < 3; ++i) {
      Vec3 e{i == 0 ? 1.0 : 0.0, i == 1 ? 1.0 : 0.0, i == 2 ? 1.0 : 0.0};
      f.axes[i] = rotate(e, axis, angle) * scale;
    }
    if (c.percent(5)) {
      const int flat = c.range(1, 3);  // axes collapsed: 1 a plane, 2 a line, 3 a point
      for (int i = 0; i < flat; ++i) f.axes[2 - i] = {0, 0, 0};
      description += flat == 1 ? "[flattened]" : flat == 2 ? "[onto a line]" : "[onto a point]";
    }
    frame_ = f;
  }

  int vertex(const Vec3& local) { return vertexAt(frame_.place(local)); }
  int vertexAt(const Vec3& world) {
    points_.push_back(world);
    pieceOf_.push_back(piece_);
    valence_.push_back(0);
    return static_cast<int>(points_.size()) - 1;
  }

  // Adds the face (fan-triangulated for Loop) when it fits the face budget and keeps every
  // vertex within maxValence; false (nothing added) otherwise.
  bool face(const std::vector<int>& vs) {
    // Faces of 3 or more distinct vertices only (limn renders a face that repeats a vertex as
    // OpenSubdiv does, but the generator's meshes keep to well-formed faces).
    if (vs.size() < 3 || static_cast<int>(vs.size()) > options_.maxFaceSize) return false;
    for (size_t i = 0; i < vs.size(); ++i) {
      if (std::count(vs.begin() + i + 1, vs.end(), vs[i])) return false;
    }
    std::vector<std::vector<int>> parts;
    if (scheme_ == Scheme::Loop && vs.size() > 3) {
      for (size_t i = 1; i + 1 < vs.size(); ++i) parts.push_back({vs[0], vs[i], vs[i + 1]});
    } else {
      parts.push_back(vs);
    }
    if (facesLeft() < static_cast<int>(parts.size())) return false;
    std::vector<int> added(points_.size(), 0);
    for (const auto& part : parts) {
      for (int v : part) {
        if (valence_[v] + ++added[v] > options_.maxValence) return false;
      }
    }
    for (auto& part : parts) {
      for (int v : part) ++valence_[v];
      faces_.push_back(std::move(part));
    }
    return true;
  }

  // Faces the next piece may still use, counted as Loop counts them.
  int facesLeft() const { return options_.maxFaces - static_cast<int>(faces_.size()); }
  // Faces an n-gon costs.
  int cost(int n) const { return scheme_ == Scheme::Loop ? n - 2 : 1; }
  int valence(int v) const { return valence_[v]; }
  int pieceOf(int v) const { return pieceOf_[v]; }
  const std::vector<Vec3>& points() const { return points_; }
  std::vector<std::vector<int>>& faces() { return faces_; }
  Scheme scheme() const { return scheme_; }
  const GeneratorOptions& options() const { return options_; }

  // Replaces `from` by `to` in every face: two vertices of different pieces become one
  // (a non-manifold vertex), when no face holds both and the valence stays within the limit.
  bool weld(int to, int from) {
    if (to == from || valence_[to] + valence_[from] > options_.maxValence) return false;
    for (const auto& f : faces_) {
      if (std::count(f.begin(), f.end(), to) && std::count(f.begin(), f.end(), from)) {
        return false;
      }
    }
    for (auto& f : faces_) std::replace(f.begin(), f.end(), from, to);
    valence_[to] += valence_[from];
    valence_[from] = 0;  // left as an isolated vertex
    return true;
  }

 private:
  Scheme scheme_;
  const GeneratorOptions& options_;
  Frame frame_;
  int piece_ = -1;
  std::vector<Vec3> points_;
  std::vector<int> pieceOf_, valence_;
  std::vector<std::vector<int>> faces_;
};

std::string str(long n) { return std::to_string(n); }

// ---------------------------------------------------------------------------------------------
// Pieces. Each takes what it needs of the face budget (shrinking itself to fit) and appends a
// word to the description.

// An open sheet of nx x ny quads (or triangles) with a noisy height; sometimes with the winding
// of the columns past a seam reversed (inconsistent orientation: non-manifold edges to
// OpenSubdiv).
void sheet(Builder& b, ChoiceSource& c, std::string& d) {
  int nx = c.range(1, 8), ny = c.range(1, 8);
  const bool triangles = b.scheme() == Scheme::Loop || c.percent(30);
  const int perQuad = triangles ? 2 : 1;
  while (nx * ny * perQuad > b.facesLeft() && (nx > 1 || ny > 1)) (nx > ny ? nx : ny)--;
  const double amplitude = c.percent(50) ? 0 : c.uniform(0, 0.5);
  const int flipFrom = c.percent(15) ? c.range(0, nx - 1) : nx;
  std::vector<int> v((nx + 1) * (ny + 1));
  for (int j = 0; j <= ny; ++j) {
    for (int i = 0; i <= nx; ++i) {
      v[j * (nx + 1) + i] =
          b.vertex({static_cast<double>(i) / nx - 0.5, static_cast<double>(j) / ny - 0.5,
                    amplitude * c.uniform(-1, 1)});
    }
  }
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      int q[4] = {v[j * (nx + 1) + i], v[j * (nx + 1) + i + 1], v[(j + 1) * (nx + 1) + i + 1],
                  v[(j + 1) * (nx + 1) + i]};
      if (i >= flipFrom) std::reverse(q, q + 4);
      if (triangles) {
        b.face({q[0], q[1], q[2]});
        b.face({q[0], q[2], q[3]});
      } else {
        b.face({q[0], q[1], q[2], q[3]});
      }
    }
  }
  d += " sheet(" + str(nx) + "x" + str(ny) + (triangles ? " tris" : "") +
       (flipFrom < nx ? " flipped" : "") + ")";
}

// A closed cube, each side n x n quads, corners jittered.
void box(Builder& b, ChoiceSource& c, std::string& d) {
  int n = c.range(1, 3);
  while (n > 1 && 6 * n * n * b.cost(4) > b.facesLeft()) --n;
  const double jitter = c.percent(50) ? 0 : c.uniform(0, 0.3) / n;
  std::vector<int> index((n + 1) * (n + 1) * (n + 1), -1);
  auto at = [&](int p[3]) {
    int& slot = index[(p[0] * (n + 1) + p[1]) * (n + 1) + p[2]];
    if (slot < 0) {
      slot = b.vertex({static_cast<double>(p[0]) / n - 0.5 + jitter * c.uniform(-1, 1),
                       static_cast<double>(p[1]) / n - 0.5 + jitter * c.uniform(-1, 1),
                       static_cast<double>(p[2]) / n - 0.5 + jitter * c.uniform(-1, 1)});
    }
    return slot;
  };
  for (int a = 0; a < 3; ++a) {
    const int b1 = (a + 1) % 3, b2 = (a + 2) % 3;
    for (int side : {0, n}) {
      for (int u = 0; u < n; ++u) {
        for (int w = 0; w < n; ++w) {
          std::vector<int> q;
          for (auto [du, dw] : {std::pair{0, 0}, {1, 0}, {1, 1}, {0, 1}}) {
            int p[3];
            p[a] = side;
            p[b1] = u + du;
            p[b2] = w + dw;
            q.push_back(at(p));
          }
          if (side == 0) std::reverse(q.begin(), q.end());  // outward normals
          b.face(q);
        }
      }
    }
  }
  d += " box(" + str(n) + ")";
}

// A closed torus of n x m quads.
void torus(Builder& b, ChoiceSource& c, std::string& d) {
  int n = c.range(3, 12), m = c.range(3, 8);
  while ((n > 3 || m > 3) && n * m * b.cost(4) > b.facesLeft()) (n > m ? n : m)--;
  std::vector<int> v(n * m);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < m; ++j) {
      const double u = 2 * M_PI * i / n, w = 2 * M_PI * j / m;
      v[i * m + j] = b.vertex({(0.5 + 0.2 * std::cos(w)) * std::cos(u),
                               (0.5 + 0.2 * std::cos(w)) * std::sin(u), 0.2 * std::sin(w)});
    }
  }
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < m; ++j) {
      const int i1 = (i + 1) % n, j1 = (j + 1) % m;
      b.face({v[i * m + j], v[i1 * m + j], v[i1 * m + j1], v[i * m + j1]});
    }
  }
  d += " torus(" + str(n) + "x" + str(m) + ")";
}

// A vertex of valence k (2 up to maxValence, mostly small): an open disc (a boundary vertex),
// a closed disc, a cone, a cone closed by an n-gon, a double cone (two such vertices, closed),
// or a fan of quads.
void fan(Builder& b, ChoiceSource& c, std::string& d) {
  const int maxValence = b.options().maxValence;
  int k = c.percent(25) ? c.range(65, std::max(65, maxValence)) : c.range(2, 64);
  const int kind =
      c.range(0, 5);  // 0 open disc, 1 closed disc, 2 cone, 3 capped, 4 double, 5 quads
  const int budget = b.facesLeft() / ((kind == 4 ? 2 : 1) * (kind == 5 ? b.cost(4) : 1));
  k = std::max(2, std::min({k, budget - (kind == 3 ? b.cost(k) : 0), maxValence}));
  if (kind == 3) k = std::max(3, std::min(k, b.options().maxFaceSize));
  const double height = kind >= 2 && kind <= 4 ? c.uniform(0.2, 1.0) : 0;
  const int center = b.vertex({0, 0, height});
  const int ringSize = kind == 5 ? 2 * k : k;
  std::vector<int> ring(ringSize);
  const double wobble = c.percent(30) ? c.uniform(0, 0.3) : 0;
  for (int i = 0; i < ringSize; ++i) {
    const double a = 2 * M_PI * i / ringSize;
    ring[i] = b.vertex({0.5 * std::cos(a), 0.5 * std::sin(a), wobble * c.uniform(-1, 1)});
  }
  // The open disc: k faces over k + 1 ring vertices, a small gap between the first and last.
  if (kind == 0) ring.push_back(b.vertex({0.5, -0.01, 0}));
  for (int i = 0; i < k; ++i) {
    if (kind == 5) {
      b.face({center, ring[2 * i], ring[2 * i + 1], ring[(2 * i + 2) % ringSize]});
    } else {
      b.face({center, ring[i], ring[kind == 0 ? i + 1 : (i + 1) % k]});
    }
  }
  if (kind == 3) {
    std::vector<int> cap(ring.rbegin(), ring.rend());
    b.face(cap);
  }
  if (kind == 4) {
    const int apex = b.vertex({0, 0, -height});
    for (int i = 0; i < k; ++i) b.face({apex, ring[(i + 1) % k], ring[i]});
  }
  const char* names[] = {"disc", "closed disc", "cone", "capped cone", "double cone", "quad fan"};
  d += std::string(" fan(") + names[kind] + ", valence " + str(k) + ")";
}

// k pages (3 up to 200) on one spine edge: an edge shared by k faces; pages one or two faces
// deep, some wound the other way, sometimes all in one plane (coincident pages).
void book(Builder& b, ChoiceSource& c, std::string& d) {
  const bool quads = b.scheme() != Scheme::Loop && c.percent(50);
  const int depth = c.percent(30) ? 2 : 1;
  const int perPage = (quads ? b.cost(4) : 1) + (depth == 2 ? b.cost(4) : 0);
  int k = c.percent(30) ? c.range(21, 200) : c.range(3, 20);
  k = std::max(3, std::min(k, b.facesLeft() / perPage));
  const bool coincident = c.percent(10);
  const int s0 = b.vertex({0, -0.5, 0}), s1 = b.vertex({0, 0.5, 0});
  for (int i = 0; i < k; ++i) {
    const double a = coincident ? 0 : 2 * M_PI * (i + c.uniform(-0.3, 0.3)) / k;
    const Vec3 out{0.5 * std::cos(a), 0, 0.5 * std::sin(a)};
    const bool flip = c.percent(30);
    int p0 = s0, p1 = s1;
    for (int layer = 1; layer <= depth; ++layer) {
      std::vector<int> page;
      if (quads || layer > 1) {
        const int q1 = b.vertex(out * layer + Vec3{0, 0.5, 0});
        const int q0 = b.vertex(out * layer + Vec3{0, -0.5, 0});
        page = {p0, p1, q1, q0};
        if (flip) std::reverse(page.begin(), page.end());
        b.face(page);
        p0 = q0;
        p1 = q1;
      } else {
        const int q = b.vertex(out);
        page = {p0, p1, q};
        if (flip) std::reverse(page.begin(), page.end());
        b.face(page);
        p0 = q;
        p1 = s1;  // a second layer goes on the page's outer edge
      }
    }
  }
  d += " book(" + str(k) + " pages" + (quads ? " quads" : "") + (depth > 1 ? " deep" : "") +
       (coincident ? " coincident" : "") + ")";
}

// m sheets (2-6) that meet at one vertex and nowhere else: bow-ties, cones of sheets, fans.
void bowtie(Builder& b, ChoiceSource& c, std::string& d) {
  const int m = c.range(2, 6);
  const int shared = b.vertex({0, 0, 0});
  std::string kinds;
  for (int s = 0; s < m; ++s) {
    const int t = std::min(c.range(1, 8), b.facesLeft());
    if (t < 1) break;
    const bool cone = t >= 3 && c.percent(40);
    const Vec3 dir = unitVector(c), side = normalize(cross(dir, unitVector(c)));
    const Vec3 up = cross(dir, side);
    const double spread = cone ? 2 * M_PI : c.uniform(0.3, 2.5);
    std::vector<int> ring;
    const int ringSize = cone ? t : t + 1;
    for (int i = 0; i < ringSize; ++i) {
      const double a = spread * i / t;
      ring.push_back(b.vertex(dir * 0.6 + (side * std::cos(a) + up * std::sin(a)) * 0.3));
    }
    for (int i = 0; i < t; ++i) b.face({shared, ring[i], ring[(i + 1) % ringSize]});
    kinds += cone ? "C" : "F";
  }
  d += " bowtie(" + kinds + ")";
}

// An n-gon (3 up to maxFaceSize): alone (planar, warped or star-shaped), a prism closed by two,
// one ringed by quads, or a pillow of two back to back (every vertex of valence 2).
void ngon(Builder& b, ChoiceSource& c, std::string& d) {
  int n = c.percent(40) ? c.range(17, b.options().maxFaceSize) : c.range(3, 16);
  const int kind = c.range(0, 3);  // 0 alone, 1 prism, 2 ringed, 3 pillow
  auto cost = [&](int m) {
    return kind == 0 ? b.cost(m) : kind == 3 ? 2 * b.cost(m) : 2 * b.cost(m) + m * b.cost(4);
  };
  while (n > 3 && cost(n) > b.facesLeft()) --n;
  const bool star = c.percent(30), warped = c.percent(30);
  std::vector<int> top, bottom;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n, r = star && i % 2 ? 0.2 : 0.5;
    const double z = warped ? c.uniform(-0.3, 0.3) : 0;
    top.push_back(b.vertex({r * std::cos(a), r * std::sin(a), z}));
  }
  if (kind == 0 || kind == 3) {
    b.face(top);
    if (kind == 3) b.face(std::vector<int>(top.rbegin(), top.rend()));
  } else if (kind == 1) {
    for (int i = 0; i < n; ++i) {
      const double a = 2 * M_PI * i / n;
      bottom.push_back(b.vertex({0.5 * std::cos(a), 0.5 * std::sin(a), -0.6}));
    }
    b.face(top);
    b.face(std::vector<int>(bottom.rbegin(), bottom.rend()));
    for (int i = 0; i < n; ++i) b.face({bottom[i], bottom[(i + 1) % n], top[(i + 1) % n], top[i]});
  } else {
    for (int i = 0; i < n; ++i) {
      const double a = 2 * M_PI * i / n;
      bottom.push_back(b.vertex({0.9 * std::cos(a), 0.9 * std::sin(a), 0}));
    }
    b.face(top);
    for (int i = 0; i < n; ++i) b.face({top[i], bottom[i], bottom[(i + 1) % n], top[(i + 1) % n]});
  }
  const char* names[] = {"alone", "prism", "ringed", "pillow"};
  d += " ngon(" + str(n) + " " + names[kind] + (star ? " star" : "") + (warped ? " warped" : "") +
       ")";
}

// Faces of zero area and coincident geometry: a face whose corners are one point, a face of
// collinear corners, a sliver, or a sheet doubled by a second sheet with its own vertices at
// the same positions.
void degenerate(Builder& b, ChoiceSource& c, std::string& d) {
  const int kind = c.range(0, 3);
  const int n = b.scheme() == Scheme::Loop ? 3 : c.range(3, 5);
  std::vector<int> f;
  if (kind == 0) {
    for (int i = 0; i < n; ++i) f.push_back(b.vertex({0.1, 0.2, 0.3}));
    b.face(f);
    d += " point-face(" + str(n) + ")";
  } else if (kind == 1) {
    for (int i = 0; i < n; ++i) f.push_back(b.vertex({0.2 * i, 0, 0}));
    b.face(f);
    d += " collinear-face(" + str(n) + ")";
  } else if (kind == 2) {
    const int a = b.vertex({0, 0, 0}), e = b.vertex({1, 0, 0}), s = b.vertex({0.5, 1e-12, 0});
    b.face({a, e, s});
    b.face({e, a, b.vertex({0.5, -0.5, 0})});
    d += " sliver";
  } else {
    const int nx = std::max(1, std::min(c.range(1, 4), b.facesLeft() / 4));
    for (int copy = 0; copy < 2; ++copy) {
      std::vector<int> v;
      for (int i = 0; i <= nx; ++i) {
        v.push_back(b.vertex({0.3 * i, 0, 0}));
        v.push_back(b.vertex({0.3 * i, 0.3, 0}));
      }
      for (int i = 0; i < nx; ++i) {
        std::vector<int> q = {v[2 * i], v[2 * i + 2], v[2 * i + 3], v[2 * i + 1]};
        if (copy == 1 && c.percent(50)) std::reverse(q.begin(), q.end());
        b.face(q);
      }
    }
    d += " doubled-sheet(" + str(nx) + ")";
  }
}

// Random faces over a small pool of vertices: any mix of non-manifold edges and vertices,
// inconsistent winding, overlapping faces.
void soup(Builder& b, ChoiceSource& c, std::string& d) {
  const int poolSize = c.range(4, 24);
  std::vector<int> pool;
  for (int i = 0; i < poolSize; ++i) {
    pool.push_back(
        c.percent(10) && i > 0
            ? b.vertexAt(b.points()[pool[c.range(0, i - 1)]])  // coincident
            : b.vertex({c.uniform(-0.5, 0.5), c.uniform(-0.5, 0.5), c.uniform(-0.5, 0.5)}));
  }
  const int faces = std::min(c.range(1, 40), b.facesLeft());
  for (int i = 0; i < faces; ++i) {
    const int n = b.scheme() == Scheme::Loop ? 3 : c.range(3, std::min(6, poolSize));
    std::vector<int> shuffled = pool;
    for (int k = 0; k < n; ++k) std::swap(shuffled[k], shuffled[c.range(k, poolSize - 1)]);
    b.face(std::vector<int>(shuffled.begin(), shuffled.begin() + n));
  }
  d += " soup(" + str(poolSize) + " vertices, " + str(faces) + " faces)";
}

// A Moebius strip: non-orientable, so its last quad meets the first against its winding.
void mobius(Builder& b, ChoiceSource& c, std::string& d) {
  int n = c.range(4, 16);
  n = std::max(3, std::min(n, b.facesLeft() / b.cost(4)));
  std::vector<int> inner, outer;
  for (int i = 0; i < n; ++i) {
    const double t = 2 * M_PI * i / n;
    const Vec3 center{0.5 * std::cos(t), 0.5 * std::sin(t), 0};
    const Vec3 radial{std::cos(t), std::sin(t), 0};
    const Vec3 offset = (radial * std::cos(t / 2) + Vec3{0, 0, 1} * std::sin(t / 2)) * 0.15;
    inner.push_back(b.vertex(center - offset));
    outer.push_back(b.vertex(center + offset));
  }
  for (int i = 0; i + 1 < n; ++i) b.face({inner[i], outer[i], outer[i + 1], inner[i + 1]});
  b.face({inner[n - 1], outer[n - 1], inner[0], outer[0]});
  d += " mobius(" + str(n) + ")";
}

// A closed UV sphere: its poles are fans of `segments` triangles.
void sphere(Builder& b, ChoiceSource& c, std::string& d) {
  int segments = c.range(3, 24), rings = c.range(2, 8);
  auto cost = [&] { return 2 * segments + (rings - 2) * segments * b.cost(4); };
  while ((segments > 3 || rings > 2) && cost() > b.facesLeft())
    (segments > rings ? segments : rings)--;
  const int north = b.vertex({0, 0, 0.5}), south = b.vertex({0, 0, -0.5});
  std::vector<std::vector<int>> v(rings - 1);
  for (int r = 1; r < rings; ++r) {
    const double phi = M_PI * r / rings;
    for (int s = 0; s < segments; ++s) {
      const double theta = 2 * M_PI * s / segments;
      v[r - 1].push_back(b.vertex({0.5 * std::sin(phi) * std::cos(theta),
                                   0.5 * std::sin(phi) * std::sin(theta), 0.5 * std::cos(phi)}));
    }
  }
  for (int s = 0; s < segments; ++s) {
    const int s1 = (s + 1) % segments;
    b.face({north, v[0][s], v[0][s1]});
    for (int r = 0; r + 1 < rings - 1; ++r) b.face({v[r][s], v[r + 1][s], v[r + 1][s1], v[r][s1]});
    b.face({south, v[rings - 2][s1], v[rings - 2][s]});
  }
  d += " sphere(" + str(segments) + "x" + str(rings) + ")";
}

// Vertices no face uses, and maybe one lone face.
void lone(Builder& b, ChoiceSource& c, std::string& d) {
  const int isolated = c.range(1, 4);
  for (int i = 0; i < isolated; ++i) b.vertex({c.uniform(-1, 1), c.uniform(-1, 1), 0});
  if (c.percent(50)) {
    const int n = b.scheme() == Scheme::Loop ? 3 : c.range(3, 4);
    std::vector<int> f;
    for (int i = 0; i < n; ++i)
      f.push_back(b.vertex({std::cos(2 * M_PI * i / n), std::sin(2 * M_PI * i / n), 0}));
    b.face(f);
  }
  d += " isolated(" + str(isolated) + ")";
}

using Piece = void (*)(Builder&, ChoiceSource&, std::string&);
const std::vector<Piece> kPieces = {sheet, box,        torus, fan,    book,   bowtie,
                                    ngon,  degenerate, soup,  mobius, sphere, lone};

// ---------------------------------------------------------------------------------------------
// Joining pieces after they are made.

void joins(Builder& b, ChoiceSource& c, std::string& d) {
  const int n = static_cast<int>(b.points().size());
  if (n < 2) return;
  // Welds: a vertex of one piece made the same vertex as one of another piece.
  const int welds = c.percent(40) ? c.range(1, 3) : 0;
  for (int i = 0; i < welds; ++i) {
    const int to = c.range(0, n - 1), from = c.range(0, n - 1);
    if (b.pieceOf(to) != b.pieceOf(from) && b.valence(to) > 0 && b.valence(from) > 0 &&
        b.weld(to, from)) {
      d += " weld";
    }
  }
  auto& faces = b.faces();
  if (faces.empty()) return;
  // Fins: pages added on an existing edge (a non-manifold edge of 3 or more faces).
  const int fins = c.percent(30) ? c.range(1, 2) : 0;
  for (int i = 0; i < fins && !faces.empty(); ++i) {
    const std::vector<int> f = faces[c.range(0, static_cast<int>(faces.size()) - 1)];
    const int k = c.range(0, static_cast<int>(f.size()) - 1);
    const int a = f[k], e = f[(k + 1) % f.size()];
    const Vec3 mid = (b.points()[a] + b.points()[e]) * 0.5;
    const int pages = c.range(1, 5);
    for (int p = 0; p < pages; ++p) {
      const Vec3 direction = unitVector(c);
      const int apex = b.vertexAt(mid + direction * c.logUniform(0.05, 0.5));
      if (c.percent(50)) {
        b.face({a, e, apex});
      } else {
        b.face({e, a, apex});
      }
    }
    d += " fin(" + str(pages) + ")";
  }
  // Duplicated faces: the same corners again, in the same, a rotated or the reverse order.
  const int duplicates = c.percent(20) ? c.range(1, 2) : 0;
  for (int i = 0; i < duplicates; ++i) {
    std::vector<int> f = faces[c.range(0, static_cast<int>(faces.size()) - 1)];
    const int how = c.range(0, 2);
    if (how == 1) std::rotate(f.begin(), f.begin() + 1, f.end());
    if (how == 2) std::reverse(f.begin(), f.end());
    if (b.face(f)) d += " duplicate-face";
  }
}

// ---------------------------------------------------------------------------------------------
// Tags.

float sharpness(ChoiceSource& c) {
  static const std::vector<float> values = {0.0f,  0.01f, 0.25f, 0.5f, 1.0f,  1.5f,
                                            2.0f,  3.7f,  5.0f,  9.5f, 9.99f, 10.0f,
                                            10.5f, 20.0f, 1e3f,  1e6f, 1e30f};
  if (c.percent(30)) return static_cast<float>(c.uniform(0, 12));
  return c.pick(values);
}

std::vector<std::pair<int, int>> edgesOf(const ControlMesh& mesh) {
  std::set<std::pair<int, int>> seen;
  std::vector<std::pair<int, int>> edges;
  size_t offset = 0;
  for (int n : mesh.faceVertexCounts) {
    for (int i = 0; i < n; ++i) {
      int a = mesh.faceVertexIndices[offset + i], e = mesh.faceVertexIndices[offset + (i + 1) % n];
      if (seen.insert({std::min(a, e), std::max(a, e)}).second) edges.push_back({a, e});
    }
    offset += n;
  }
  return edges;
}

void tags(ControlMesh& mesh, ChoiceSource& c, std::string& d) {
  const std::vector<std::pair<int, int>> edges = edgesOf(mesh);
  if (!edges.empty() && c.percent(60)) {
    const int count = c.range(1, std::min(40, static_cast<int>(edges.size())));
    const float common = sharpness(c);
    const bool same = c.percent(40);
    for (int i = 0; i < count; ++i) {
      auto [a, e] = c.percent(30) && !mesh.creases.empty() && i > 0
                        ? std::pair{mesh.creases.back().v1, mesh.creases.back().v0}  // again
                        : edges[c.range(0, static_cast<int>(edges.size()) - 1)];
      if (c.percent(30)) std::swap(a, e);
      mesh.creases.push_back({a, e, same ? common : sharpness(c)});
    }
    // Every edge of one face creased: a crease loop.
    if (c.percent(30)) {
      const int f = c.range(0, mesh.faceCount() - 1);
      size_t offset = 0;
      for (int i = 0; i < f; ++i) offset += mesh.faceVertexCounts[i];
      const int n = mesh.faceVertexCounts[f];
      for (int i = 0; i < n; ++i) {
        mesh.creases.push_back({mesh.faceVertexIndices[offset + i],
                                mesh.faceVertexIndices[offset + (i + 1) % n], common});
      }
    }
    d += " creases(" + str(static_cast<long>(mesh.creases.size())) + ")";
  }
  if (c.percent(40)) {
    const int count = c.range(1, 10);
    for (int i = 0; i < count; ++i) {
      mesh.corners.push_back({c.range(0, mesh.vertexCount() - 1), sharpness(c)});
    }
    d += " corners(" + str(count) + ")";
  }
  if (mesh.faceCount() > 1 && c.percent(35)) {
    const int count = c.range(1, std::min(20, mesh.faceCount() - 1));
    std::set<int> distinct;
    for (int i = 0; i < count; ++i) {
      const int f = c.range(0, mesh.faceCount() - 1);
      // At least one face stays: every face a hole is refused (and made on purpose below).
      if (!distinct.count(f) && static_cast<int>(distinct.size()) + 1 >= mesh.faceCount()) break;
      distinct.insert(f);
      mesh.holes.push_back(f);
    }
    d += " holes(" + str(static_cast<long>(mesh.holes.size())) + ")";
  }
  const BoundaryInterpolation rules[] = {BoundaryInterpolation::None,
                                         BoundaryInterpolation::EdgeOnly,
                                         BoundaryInterpolation::EdgeAndCorner};
  mesh.boundary = rules[c.range(0, 2)];
  mesh.creaseMethod = c.percent(30) ? CreaseMethod::Chaikin : CreaseMethod::Uniform;
  mesh.triangleSubdivision =
      c.percent(30) ? TriangleSubdivision::Smooth : TriangleSubdivision::CatmullClark;
}

// ---------------------------------------------------------------------------------------------
// Invalid on purpose: one defect that limn must refuse with a 4xx.

std::string breakMesh(ControlMesh& mesh, ChoiceSource& c, const GeneratorOptions& options) {
  auto addPoint = [&](const Vec3& p) {
    mesh.points.push_back(p);
    return mesh.vertexCount() - 1;
  };
  auto addFace = [&](const std::vector<int>& f) {
    mesh.faceVertexCounts.push_back(static_cast<int>(f.size()));
    mesh.faceVertexIndices.insert(mesh.faceVertexIndices.end(), f.begin(), f.end());
  };
  switch (c.range(0, 10)) {
    case 0: {  // a vertex no face touches cannot be on an edge
      const int isolated = addPoint({0, 0, 0});
      mesh.creases.push_back({mesh.faceVertexIndices[0], isolated, 1.0f});
      return "crease off the mesh's edges";
    }
    case 1:
      mesh.holes.push_back(mesh.faceCount());
      return "hole past the last face";
    case 2:
      mesh.corners.push_back({mesh.vertexCount(), 2.0f});
      return "corner past the last vertex";
    case 3: {
      const auto edges = edgesOf(mesh);
      mesh.creases.push_back({edges[0].first, edges[0].second, -1.0f});
      return "negative crease sharpness";
    }
    case 4: {
      std::vector<int> f;
      for (int i = 0; i <= options.maxFaceSize; ++i) {
        const double a = 2 * M_PI * i / (options.maxFaceSize + 1);
        f.push_back(addPoint({std::cos(a), std::sin(a), 3}));
      }
      addFace(f);
      return "face over maxFaceSize";
    }
    case 5: {
      const int center = addPoint({0, 0, 4});
      std::vector<int> ring;
      const int k = options.limitValence + 1;
      for (int i = 0; i < k; ++i) {
        ring.push_back(addPoint({std::cos(2 * M_PI * i / k), std::sin(2 * M_PI * i / k), 4}));
      }
      for (int i = 0; i < k; ++i) addFace({center, ring[i], ring[(i + 1) % k]});
      return "vertex over maxValence";
    }
    case 6:
      if (mesh.scheme == Scheme::Loop) {
        addFace(
            {addPoint({0, 0, 5}), addPoint({1, 0, 5}), addPoint({1, 1, 5}), addPoint({0, 1, 5})});
        return "a quad for the loop scheme";
      }
      [[fallthrough]];
    case 7:
      mesh.holes.clear();
      for (int f = 0; f < mesh.faceCount(); ++f) mesh.holes.push_back(f);
      return "every face a hole";
    case 8:
      addFace({0, 1 % mesh.vertexCount(), mesh.vertexCount()});
      return "face past the last vertex";
    case 9:
      addFace({addPoint({1e16, 0, 0}), addPoint({1, 0, 0}), addPoint({0, 1, 0})});
      return "coordinate beyond 1e15";
    default:
      addFace({addPoint({0, 0, 6}), addPoint({1, 0, 6})});
      return "face of two vertices";
  }
}

// ---------------------------------------------------------------------------------------------
// OBJ text, in the forms limn's reader accepts: absolute or relative face indices, `w` or
// colours after the coordinates, comments and skipped statements between lines, CRLF, tags
// before or after the faces, several elements per tag line with one sharpness for all or one
// each, and every spelling of the boundary, crease and triangle rules.

std::string number(double x) {
  char text[40];
  std::snprintf(text, sizeof text, "%.17g", x);
  return text;
}

std::string number(float x) {
  char text[40];
  std::snprintf(text, sizeof text, "%.9g", static_cast<double>(x));  // reads back as the float
  return text;
}

// Calls write(first, count) for runs of 1-8 consecutive elements: one tag line each.
void inRuns(size_t size, ChoiceSource& c, const std::function<void(size_t, size_t)>& write) {
  for (size_t i = 0; i < size;) {
    const size_t count = std::min(size - i, static_cast<size_t>(c.percent(50) ? 1 : c.range(1, 8)));
    write(i, count);
    i += count;
  }
}

// Writes `mesh` (its points as `vertexLines` too).
std::string writeObj(const ControlMesh& mesh, ChoiceSource& c, bool absoluteOnly,
                     std::string& vertexLines) {
  const std::string eol = c.percent(10) ? "\r\n" : "\n";
  const bool relative = !absoluteOnly && c.percent(20);
  const int vertexExtra = c.percent(90) ? 0 : c.range(1, 2);  // 1: w, 2: r g b
  std::string out = "# limn generated mesh" + eol;
  if (c.percent(20)) out += "o piece" + eol;
  for (const Vec3& p : mesh.points) {
    vertexLines += "v " + number(p.x) + " " + number(p.y) + " " + number(p.z);
    if (vertexExtra == 1) vertexLines += " 1";
    if (vertexExtra == 2) vertexLines += " 0.5 0.25 1";
    vertexLines += eol;
  }
  out += vertexLines;

  // "t crease 2k/1/0 a b ... s" or "2k/k/0 a b ... s1 ... sk"; corners alike; holes n/0/0.
  std::string tagText;
  auto sharpnesses = [&](size_t i, size_t n, auto sharpnessOf) {
    bool same = true;
    for (size_t k = i; k < i + n; ++k) same = same && sharpnessOf(k) == sharpnessOf(i);
    const bool one = same && c.percent(70);
    std::string values;
    for (size_t k = i; k < (one ? i + 1 : i + n); ++k) values += " " + number(sharpnessOf(k));
    return std::pair{one ? std::string("1") : str(static_cast<long>(n)), values};
  };
  inRuns(mesh.creases.size(), c, [&](size_t i, size_t n) {
    std::string ints;
    for (size_t k = i; k < i + n; ++k) {
      ints += " " + str(mesh.creases[k].v0) + " " + str(mesh.creases[k].v1);
    }
    auto [floats, values] = sharpnesses(i, n, [&](size_t k) { return mesh.creases[k].sharpness; });
    tagText +=
        "t crease " + str(static_cast<long>(2 * n)) + "/" + floats + "/0" + ints + values + eol;
  });
  inRuns(mesh.corners.size(), c, [&](size_t i, size_t n) {
    std::string ints;
    for (size_t k = i; k < i + n; ++k) ints += " " + str(mesh.corners[k].vertex);
    auto [floats, values] = sharpnesses(i, n, [&](size_t k) { return mesh.corners[k].sharpness; });
    tagText += "t corner " + str(static_cast<long>(n)) + "/" + floats + "/0" + ints + values + eol;
  });
  inRuns(mesh.holes.size(), c, [&](size_t i, size_t n) {
    tagText += "t hole " + str(static_cast<long>(n)) + "/0/0";
    for (size_t k = i; k < i + n; ++k) tagText += " " + str(mesh.holes[k]);
    tagText += eol;
  });
  // Without a tag the boundary is edge-only: leave it out now and then.
  if (mesh.boundary != BoundaryInterpolation::EdgeOnly || c.percent(60)) {
    const int code = mesh.boundary == BoundaryInterpolation::None            ? 0
                     : mesh.boundary == BoundaryInterpolation::EdgeAndCorner ? 1
                                                                             : 2;
    tagText += "t interpolateboundary 1/0/0 " + str(code) + eol;
  }
  if (mesh.creaseMethod == CreaseMethod::Chaikin) {
    tagText += "t creasemethod 0/0/1 chaikin" + eol;
  } else if (c.percent(30)) {
    tagText += std::string("t creasemethod 0/0/1 ") + (c.percent(50) ? "normal" : "uniform") + eol;
  }
  if (mesh.triangleSubdivision == TriangleSubdivision::Smooth) {
    tagText += "t smoothtriangles 0/0/1 smooth" + eol;
  } else if (c.percent(30)) {
    tagText += std::string("t smoothtriangles 0/0/1 ") +
               (c.percent(50) ? "catmark" : "catmull-clark") + eol;
  }
  if (c.percent(10)) tagText += "t faceedit 0/0/0" + eol;  // unsupported: a warning

  const bool tagsFirst = c.percent(20);
  if (tagsFirst) out += tagText;
  if (c.percent(30)) out += "g faces" + eol + "s off" + eol;
  const long n = mesh.vertexCount();
  size_t offset = 0;
  for (size_t f = 0; f < mesh.faceVertexCounts.size(); ++f) {
    if (c.percent(2)) out += "# face " + str(static_cast<long>(f)) + eol;
    out += "f";
    for (int k = 0; k < mesh.faceVertexCounts[f]; ++k) {
      const long v = mesh.faceVertexIndices[offset + k];
      out += " " + str(relative ? v - n : v + 1);
    }
    out += eol;
    offset += mesh.faceVertexCounts[f];
  }
  if (!tagsFirst) out += tagText;
  return out;
}

}  // namespace

// ---------------------------------------------------------------------------------------------

GeneratedMesh generateMesh(ChoiceSource& c, const GeneratorOptions& options) {
  GeneratedMesh out;
  ControlMesh& mesh = out.mesh;
  const int scheme = c.range(0, 3);  // catmull-clark twice as often
  mesh.scheme = scheme == 2 ? Scheme::Loop : scheme == 3 ? Scheme::Bilinear : Scheme::CatmullClark;
  std::string& d = out.description;
  d = schemeName(mesh.scheme) + std::string(":");

  Builder b(mesh.scheme, options);
  const int pieces = c.range(1, options.maxPieces);
  for (int i = 0; i < pieces && b.facesLeft() > 0; ++i) {
    b.newPiece(c, d);
    c.pick(kPieces)(b, c, d);
  }
  joins(b, c, d);
  if (b.faces().empty()) {  // every piece was isolated vertices or over budget: one triangle
    const int a = b.vertexAt({0, 0, 0}), e = b.vertexAt({1, 0, 0}), f = b.vertexAt({0, 1, 0});
    b.face({a, e, f});
    d += " triangle";
  }
  if (c.percent(10)) {  // all of it scaled far down or up
    const double s = c.percent(50) ? c.logUniform(1e-9, 1e-4) : c.logUniform(1e4, 1e9);
    for (Vec3 p : b.points()) mesh.points.push_back(p * s);
    d += " scaled(" + number(s) + ")";
  } else {
    mesh.points = b.points();
  }
  for (const auto& f : b.faces()) {
    mesh.faceVertexCounts.push_back(static_cast<int>(f.size()));
    mesh.faceVertexIndices.insert(mesh.faceVertexIndices.end(), f.begin(), f.end());
  }
  tags(mesh, c, d);
  if (c.percent(options.invalidPercent)) {
    out.refusal = breakMesh(mesh, c, options);
    d += " INVALID(" + out.refusal + ")";
  }
  std::string vertexLines;
  out.obj = writeObj(mesh, c, !out.refusal.empty(), vertexLines);
  // tinyobjloader reads decimals digit by digit, not correctly rounded: a coordinate printed
  // to 17 digits may come back an ulp or so away. The mesh's points are what the reader reads.
  MeshLimits unlimited;
  unlimited.maxVertices = mesh.vertexCount();
  mesh.points = formats::parseObj(vertexLines, mesh.scheme, unlimited).mesh.points;
  return out;
}

GeneratedMesh generateMesh(uint64_t seed, const GeneratorOptions& options) {
  SeededChoices choices(seed);
  GeneratedMesh mesh = generateMesh(choices, options);
  mesh.description = "seed " + std::to_string(seed) + " " + mesh.description;
  return mesh;
}

std::string jsonString(std::string_view text) {
  std::string out = "\"";
  for (char ch : text) {
    switch (ch) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\r':
        out += "\\r";
        break;
      case '\t':
        out += "\\t";
        break;
      default:
        if (static_cast<unsigned char>(ch) < 0x20) {
          char escaped[8];
          std::snprintf(escaped, sizeof escaped, "\\u%04x", ch);
          out += escaped;
        } else {
          out += ch;
        }
    }
  }
  return out + "\"";
}

std::string objMeshJson(const GeneratedMesh& mesh) {
  return std::string(R"({"format": "obj", "scheme": ")") + schemeName(mesh.mesh.scheme) +
         R"(", "data": )" + jsonString(mesh.obj) + "}";
}

// ---------------------------------------------------------------------------------------------
// Requests

namespace {

// (Every choice below is made in a statement of its own: the operands of a + chain, or a
// function's arguments, are evaluated in an order the compiler picks, and gcc and clang pick
// differently, which would give one fuzz input other requests in each build.)
std::string cameraJson(ChoiceSource& c, const VariantOptions& options) {
  const std::string size =
      R"("width": )" + str(options.side) + R"(, "height": )" + str(options.side);
  const int kind = c.percent(60) ? 0 : c.range(1, 4);
  if (kind == 1) {  // from another side; with eyeInside, from inside the bounding sphere too
    const double azimuth = c.uniform(-180, 180);
    const double elevation = c.uniform(-90, 90);
    const double distance = c.logUniform(options.eyeInside ? 0.2 : 1.2, 5);
    return R"({"orbit": {"azimuthDeg": )" + number(azimuth) + R"(, "elevationDeg": )" +
           number(elevation) + R"(, "distance": )" + number(distance) + "}, " + size + "}";
  }
  if (kind == 2) {
    const double azimuth = c.uniform(-180, 180);
    const double elevation = c.uniform(-89, 89);
    return R"({"projection": "orthographic", "orbit": {"azimuthDeg": )" + number(azimuth) +
           R"(, "elevationDeg": )" + number(elevation) + "}, " + size + "}";
  }
  if (kind == 3) {
    const double fov = c.uniform(10, 150);
    if (options.eyeInside) {  // the eye at the origin, inside or next to most meshes
      return R"({"eye": [0, 0, 0], "target": [0.3, 1, 0.2], "fovYDeg": )" + number(fov) + ", " +
             size + "}";
    }
    return R"({"orbit": {"azimuthDeg": 30, "elevationDeg": 20}, "fovYDeg": )" + number(fov) + ", " +
           size + "}";
  }
  if (kind == 4) {
    return R"({"orbit": {"azimuthDeg": 0, "elevationDeg": 90}, "up": [0, 0, 1], )" + size + "}";
  }
  return "{" + size + "}";
}

std::string outputsJson(ChoiceSource& c, const std::string& method, bool reference) {
  std::vector<std::string> outputs = {"color"};
  if (c.percent(30)) outputs.push_back("mask");
  if (c.percent(20)) outputs.push_back("depth");
  if (c.percent(20)) outputs.push_back("normal");
  if (c.percent(15)) outputs.push_back("wireframe");
  if (method != "limit" && c.percent(15)) outputs.push_back("cage");
  if (method == "silhouette" && c.percent(30)) outputs.push_back("contours");
  if (method == "patches" && c.percent(30)) outputs.push_back("patches");
  if (reference && method != "limit" && c.percent(30)) outputs.push_back("diff");
  std::string out = "[";
  for (size_t i = 0; i < outputs.size(); ++i) out += (i ? ", \"" : "\"") + outputs[i] + "\"";
  return out + "]";
}

// normal-map: per-pixel limit normals, drawn by coarse and silhouette only (400 for others).
std::string shadingJson(ChoiceSource& c, const std::string& method) {
  const bool normalMap = method == "coarse" || method == "silhouette";
  static const std::vector<std::string> shadings = {"smooth", "flat", "normal-map"};
  if (c.percent(70)) return "";
  const std::string& shading = shadings[c.range(0, normalMap ? 2 : 1)];
  return R"(, "shading": ")" + shading + "\"";
}

std::string displacementJson(ChoiceSource& c) {
  if (!c.percent(10)) return "";
  const char* function = c.percent(50) ? "bumps" : "ripples";
  const double amplitude = c.uniform(0.001, 0.05);
  const double frequency = c.uniform(1, 8);
  return std::string(R"(, "displacement": {"function": ")") + function + R"(", "amplitude": )" +
         number(amplitude) + R"(, "frequency": )" + number(frequency) + "}";
}

// The params of `method` ("level" is drawn once per mesh and passed in).
std::string paramsJson(ChoiceSource& c, const std::string& method, const std::string& engine,
                       int level, const std::string& tessellator) {
  std::vector<std::string> p;
  if (method == "uniform") {
    p.push_back(R"("level": )" + str(level));
    p.push_back(R"("engine": ")" + engine + "\"");
    if (c.percent(25)) p.push_back(R"("pushToLimit": true)");
  } else if (method == "adaptive" || method == "patches") {
    static const std::vector<std::string> rates = {"1", "2", "4", "0.5"};
    if (c.percent(60)) p.push_back(R"("dicingRate": )" + c.pick(rates));
    if (method == "patches") {
      p.push_back(R"("tessellator": ")" + tessellator + "\"");
      if (c.percent(50)) p.push_back(R"("isolation": )" + str(c.range(1, 6)));
      if (c.percent(20)) p.push_back(R"("cullPatches": false)");
    }
  } else if (method == "silhouette") {
    if (c.percent(40))
      p.push_back(std::string(R"("contour": ")") + (c.percent(50) ? "pn" : "exact") + "\"");
    if (c.percent(30))
      p.push_back(R"("presubdivide": )" +
                  (c.percent(30) ? std::string("\"auto\"") : str(c.range(0, 1))));
    if (c.percent(20)) p.push_back(R"("searchSteps": )" + str(c.range(0, 10)));
    if (c.percent(20)) p.push_back(R"("curveSamples": )" + str(c.range(0, 48)));
  }
  if (c.percent(10)) p.push_back(R"("metricSupersample": )" + str(c.range(1, 4)));
  std::string out = "{";
  for (size_t i = 0; i < p.size(); ++i) out += (i ? ", " : "") + p[i];
  return out + "}";
}

}  // namespace

std::vector<RequestVariant> requestVariants(const GeneratedMesh& generated, ChoiceSource& c,
                                            const VariantOptions& options) {
  const std::string mesh = objMeshJson(generated);
  const int level = c.range(0, 3);
  struct Entry {
    std::string method, engine, tessellator;
  };
  const std::vector<Entry> entries = {
      {"coarse", "", ""},          {"uniform", "opensubdiv", ""}, {"uniform", "masks", ""},
      {"uniform", "factored", ""}, {"adaptive", "", ""},          {"silhouette", "", ""},
      {"patches", "", "cpu"},      {"patches", "", "gpu"},        {"limit", "", ""}};
  std::vector<int> valence(generated.mesh.points.size(), 0);
  for (int v : generated.mesh.faceVertexIndices) {
    if (v >= 0 && v < static_cast<int>(valence.size())) ++valence[v];
  }
  const bool patches = valence.empty() || *std::max_element(valence.begin(), valence.end()) <=
                                              options.maxPatchesValence;
  std::vector<RequestVariant> out;
  for (const Entry& e : entries) {
    const bool reference = c.percent(options.referencePercent);
    std::string label = e.method;
    if (!e.engine.empty()) label += " " + e.engine + " level " + str(level);
    if (!e.tessellator.empty()) label += " " + e.tessellator;
    if (reference) label += " reference";
    const std::string camera = cameraJson(c, options);
    const std::string params = paramsJson(c, e.method, e.engine, level, e.tessellator);
    const std::string outputs = outputsJson(c, e.method, reference);
    const std::string shading = shadingJson(c, e.method);
    std::string body = R"({"mesh": )" + mesh + R"(, "method": ")" + e.method + R"(", "camera": )" +
                       camera + R"(, "params": )" + params + R"(, "outputs": )" + outputs + shading;
    if (e.method == "adaptive" || e.method == "patches" ||
        (options.displacedReference && e.method == "limit")) {
      const std::string displacement = displacementJson(c);
      // Without displacedReference, a displaced surface is not also ray-cast.
      if (options.displacedReference || !reference) body += displacement;
    }
    if (reference) body += R"(, "reference": true)";
    if (c.percent(5)) body += R"(, "imageFormat": "exr")";
    if (e.method == "patches" && !patches) continue;  // made, so that the choices stay in step
    out.push_back({"/v1/render", "", label, body + "}"});
  }
  if (c.percent(options.tessellatePercent)) {
    static const std::vector<std::string> methods = {"coarse", "uniform", "adaptive", "silhouette",
                                                     "patches"};
    static const std::vector<std::string> accepts = {"model/gltf-binary", "application/x-ply",
                                                     "text/plain", ""};
    std::string method = c.pick(methods);
    if (method == "patches" && !patches) method = "adaptive";
    const std::string& accept = c.pick(accepts);
    const std::string camera = cameraJson(c, options);
    const char* engine = c.percent(50) ? "opensubdiv" : "masks";
    const std::string params = paramsJson(c, method, engine, level, "cpu");
    out.push_back({"/v1/tessellate", accept, "tessellate " + method,
                   R"({"mesh": )" + mesh + R"(, "method": ")" + method + R"(", "camera": )" +
                       camera + R"(, "params": )" + params + "}"});
  }
  if (c.percent(options.silhouettePercent)) {
    const bool svg = c.percent(50);
    const std::string camera = cameraJson(c, options);
    const std::string params = paramsJson(c, "silhouette", "", level, "");
    out.push_back({"/v1/silhouette", "",
                   std::string("silhouette endpoint ") + (svg ? "svg" : "json"),
                   R"({"mesh": )" + mesh + R"(, "camera": )" + camera + R"(, "params": )" + params +
                       R"(, "format": ")" + (svg ? "svg" : "json") + "\"}"});
  }
  if (c.percent(options.comparePercent)) {
    std::string methods = R"(["coarse", {"method": "uniform", "params": {"level": )" + str(level) +
                          R"(}}, "adaptive")";
    if (c.percent(50)) methods += R"(, "silhouette")";
    if (c.percent(50) && patches) {
      methods += R"(, {"method": "patches", "params": {"tessellator": "cpu"}})";
    }
    methods += "]";
    std::string cameras = cameraJson(c, options);
    if (c.percent(30)) cameras += ", " + cameraJson(c, options);
    out.push_back({"/v1/compare", "", "compare",
                   R"({"mesh": )" + mesh + R"(, "cameras": [)" + cameras + R"(], "methods": )" +
                       methods + "}"});
  }
  return out;
}

}  // namespace limn::testing
