#include "formats/mesh_writers.h"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>

namespace limn::formats {

namespace {

using render::tessellate::TriangleMesh;

void append(std::string& out, const void* data, size_t bytes) {
  out.append(static_cast<const char*>(data), bytes);
}

void appendU32(std::string& out, uint32_t v) {
  const unsigned char b[4] = {static_cast<unsigned char>(v), static_cast<unsigned char>(v >> 8),
                              static_cast<unsigned char>(v >> 16),
                              static_cast<unsigned char>(v >> 24)};
  append(out, b, 4);
}

void appendF32(std::string& out, float v) {
  uint32_t bits;
  std::memcpy(&bits, &v, 4);
  appendU32(out, bits);
}

std::string number(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.9g", v);
  return text;
}

}  // namespace

std::string writeGlb(const TriangleMesh& mesh, const std::string& extrasJson) {
  const size_t n = mesh.positions.size(), t = mesh.triangleCount();
  const bool normals = mesh.normals.size() == n && n > 0;
  float lo[3] = {std::numeric_limits<float>::max(), std::numeric_limits<float>::max(),
                 std::numeric_limits<float>::max()};
  float hi[3] = {-lo[0], -lo[1], -lo[2]};
  std::string bin;
  bin.reserve(n * (normals ? 24 : 12) + t * 12);
  for (const auto& p : mesh.positions) {
    const float c[3] = {p.x, p.y, p.z};
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], c[k]);
      hi[k] = std::max(hi[k], c[k]);
      appendF32(bin, c[k]);
    }
  }
  if (normals) {
    for (const auto& v : mesh.normals) {
      appendF32(bin, v.x);
      appendF32(bin, v.y);
      appendF32(bin, v.z);
    }
  }
  for (uint32_t i : mesh.indices) appendU32(bin, i);

  std::string json = R"({"asset":{"version":"2.0","generator":"limn")";
  if (!extrasJson.empty()) json += ",\"extras\":" + extrasJson;
  json += "}";
  if (t == 0) {
    json += R"(,"scene":0,"scenes":[{"nodes":[]}]})";
  } else {
    const size_t positionBytes = n * 12, normalBytes = normals ? n * 12 : 0;
    json += R"(,"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],)";
    json += R"("meshes":[{"primitives":[{"attributes":{"POSITION":0)";
    json +=
        normals ? R"(,"NORMAL":1},"indices":2,"mode":4}]}],)" : R"(},"indices":1,"mode":4}]}],)";
    json += R"("buffers":[{"byteLength":)" + std::to_string(bin.size()) + "}],";
    json += R"("bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":)" +
            std::to_string(positionBytes) + R"(,"target":34962})";
    if (normals) {
      json += R"(,{"buffer":0,"byteOffset":)" + std::to_string(positionBytes) +
              R"(,"byteLength":)" + std::to_string(normalBytes) + R"(,"target":34962})";
    }
    json += R"(,{"buffer":0,"byteOffset":)" + std::to_string(positionBytes + normalBytes) +
            R"(,"byteLength":)" + std::to_string(t * 12) + R"(,"target":34963}],)";
    json += R"("accessors":[{"bufferView":0,"componentType":5126,"count":)" + std::to_string(n) +
            R"(,"type":"VEC3","min":[)" + number(lo[0]) + "," + number(lo[1]) + "," +
            number(lo[2]) + R"(],"max":[)" + number(hi[0]) + "," + number(hi[1]) + "," +
            number(hi[2]) + "]}";
    if (normals) {
      json += R"(,{"bufferView":1,"componentType":5126,"count":)" + std::to_string(n) +
              R"(,"type":"VEC3"})";
    }
    json += R"(,{"bufferView":)" + std::to_string(normals ? 2 : 1) +
            R"(,"componentType":5125,"count":)" + std::to_string(3 * t) + R"(,"type":"SCALAR"}]})";
  }
  while (json.size() % 4) json += ' ';  // chunks are 4-byte aligned; JSON pads with spaces

  std::string out;
  const size_t total = 12 + 8 + json.size() + (t == 0 ? 0 : 8 + bin.size());
  out.reserve(total);
  appendU32(out, 0x46546C67);  // "glTF"
  appendU32(out, 2);
  appendU32(out, static_cast<uint32_t>(total));
  appendU32(out, static_cast<uint32_t>(json.size()));
  appendU32(out, 0x4E4F534A);  // "JSON"
  out += json;
  if (t != 0) {
    appendU32(out, static_cast<uint32_t>(bin.size()));
    appendU32(out, 0x004E4942);  // "BIN\0"
    out += bin;
  }
  return out;
}

std::string writePly(const TriangleMesh& mesh, const std::vector<std::string>& comments) {
  const bool normals = mesh.normals.size() == mesh.positions.size();
  std::string out = "ply\nformat binary_little_endian 1.0\n";
  for (const std::string& c : comments) {
    std::string line = c;
    std::replace(line.begin(), line.end(), '\n', ' ');
    out += "comment " + line + "\n";
  }
  out += "element vertex " + std::to_string(mesh.positions.size()) +
         "\nproperty float x\nproperty float y\nproperty float z\n";
  if (normals) out += "property float nx\nproperty float ny\nproperty float nz\n";
  out += "element face " + std::to_string(mesh.triangleCount()) +
         "\nproperty list uchar uint vertex_indices\nend_header\n";
  for (size_t i = 0; i < mesh.positions.size(); ++i) {
    const auto& p = mesh.positions[i];
    appendF32(out, p.x);
    appendF32(out, p.y);
    appendF32(out, p.z);
    if (normals) {
      appendF32(out, mesh.normals[i].x);
      appendF32(out, mesh.normals[i].y);
      appendF32(out, mesh.normals[i].z);
    }
  }
  for (size_t t = 0; t < mesh.triangleCount(); ++t) {
    out += '\3';
    for (int k = 0; k < 3; ++k) appendU32(out, mesh.indices[3 * t + k]);
  }
  return out;
}

std::string writeObjMesh(const TriangleMesh& mesh, const std::vector<std::string>& comments) {
  const bool normals = mesh.normals.size() == mesh.positions.size();
  std::string out;
  out.reserve(mesh.positions.size() * (normals ? 64 : 32) + mesh.indices.size() * 12);
  for (const std::string& c : comments) {
    std::string line = c;
    std::replace(line.begin(), line.end(), '\n', ' ');
    out += "# " + line + "\n";
  }
  char text[128];
  for (const auto& p : mesh.positions) {
    std::snprintf(text, sizeof text, "v %.9g %.9g %.9g\n", p.x, p.y, p.z);
    out += text;
  }
  if (normals) {
    for (const auto& n : mesh.normals) {
      std::snprintf(text, sizeof text, "vn %.7g %.7g %.7g\n", n.x, n.y, n.z);
      out += text;
    }
  }
  for (size_t t = 0; t < mesh.triangleCount(); ++t) {
    const uint32_t a = mesh.indices[3 * t] + 1, b = mesh.indices[3 * t + 1] + 1,
                   c = mesh.indices[3 * t + 2] + 1;
    if (normals) {
      std::snprintf(text, sizeof text, "f %u//%u %u//%u %u//%u\n", a, a, b, b, c, c);
    } else {
      std::snprintf(text, sizeof text, "f %u %u %u\n", a, b, c);
    }
    out += text;
  }
  return out;
}

}  // namespace limn::formats
