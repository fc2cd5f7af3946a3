#include "render/implicit/cube_table.h"

#include <map>
#include <stdexcept>

#include "render/core/vec.h"

namespace limn::render::implicit {

namespace {

// Each face: its four corners counter-clockwise seen from outside the cube.
constexpr int kFaces[6][4] = {
    {0, 4, 6, 2},  // x = 0
    {1, 3, 7, 5},  // x = 1
    {0, 1, 5, 4},  // y = 0
    {2, 6, 7, 3},  // y = 1
    {0, 2, 3, 1},  // z = 0
    {4, 5, 7, 6},  // z = 1
};

int edgeBetween(int a, int b) {
  const auto& edges = cubeEdges();
  for (int e = 0; e < 12; ++e) {
    if ((edges[e].a == a && edges[e].b == b) || (edges[e].a == b && edges[e].b == a)) return e;
  }
  throw std::logic_error("cube corners without an edge");
}

Vec3 cornerPosition(int c) { return {double(c & 1), double((c >> 1) & 1), double((c >> 2) & 1)}; }

// The segments of one configuration: next[e] = the edge the loop goes to after edge e.
std::map<int, int> segments(int configuration) {
  std::map<int, int> next;
  auto inside = [&](int c) { return (configuration >> c) & 1; };
  for (const auto& face : kFaces) {
    // Walk the face's boundary; each run of inside corners is cut off by its own segment, from
    // the edge where the walk leaves it to the edge where it entered.
    int start = 0;
    while (start < 4 && inside(face[start])) ++start;
    if (start == 4) continue;  // all inside
    int enter = -1;
    for (int step = 0; step < 4; ++step) {
      int c0 = face[(start + step) % 4], c1 = face[(start + step + 1) % 4];
      if (inside(c0) == inside(c1)) continue;
      int edge = edgeBetween(c0, c1);
      if (inside(c1)) {
        enter = edge;
      } else {
        next[edge] = enter;  // exit -> enter
      }
    }
  }
  return next;
}

}  // namespace

const std::array<CubeEdge, 12>& cubeEdges() {
  static const std::array<CubeEdge, 12> edges = {{
      {0, 1, 0},
      {2, 3, 0},
      {4, 5, 0},
      {6, 7, 0},  // x
      {0, 2, 1},
      {1, 3, 1},
      {4, 6, 1},
      {5, 7, 1},  // y
      {0, 4, 2},
      {1, 5, 2},
      {2, 6, 2},
      {3, 7, 2},  // z
  }};
  return edges;
}

const CubeTable& CubeTable::instance() {
  static const CubeTable table;
  return table;
}

CubeTable::CubeTable() {
  for (int configuration = 0; configuration < 256; ++configuration) {
    std::map<int, int> next = segments(configuration);
    std::vector<uint8_t>& out = cases_[configuration];
    while (!next.empty()) {
      std::vector<int> loop;
      int edge = next.begin()->first;
      while (next.count(edge)) {
        loop.push_back(edge);
        int following = next[edge];
        next.erase(edge);
        edge = following;
      }
      for (size_t i = 1; i + 1 < loop.size(); ++i) {
        out.push_back(static_cast<uint8_t>(loop[0]));
        out.push_back(static_cast<uint8_t>(loop[i]));
        out.push_back(static_cast<uint8_t>(loop[i + 1]));
      }
    }
  }
  // Orientation check on the simplest case: corner 0 inside, so outside lies towards (1, 1, 1).
  const auto& edges = cubeEdges();
  auto mid = [&](int e) { return (cornerPosition(edges[e].a) + cornerPosition(edges[e].b)) * 0.5; };
  const std::vector<uint8_t>& t = cases_[1];
  Vec3 n = cross(mid(t[1]) - mid(t[0]), mid(t[2]) - mid(t[0]));
  if (dot(n, Vec3{1, 1, 1}) < 0) {
    for (auto& triangles : cases_) {
      for (size_t i = 0; i < triangles.size(); i += 3)
        std::swap(triangles[i + 1], triangles[i + 2]);
    }
  }
}

}  // namespace limn::render::implicit
