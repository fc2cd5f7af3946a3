#include "formats/import_preflight.h"

#include <rapidjson/document.h>

#include <charconv>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "render/core/error.h"

namespace limn::formats {

namespace {

using render::InputError;
using render::mesh::MeshLimits;

constexpr uint64_t kHuge = std::numeric_limits<uint64_t>::max();

// a * b, saturating: declared counts are the attacker's numbers.
uint64_t times(uint64_t a, uint64_t b) { return (b != 0 && a > kHuge / b) ? kHuge : a * b; }
uint64_t plus(uint64_t a, uint64_t b) { return a > kHuge - b ? kHuge : a + b; }

[[noreturn]] void dishonest(ImportFormat format, const std::string& what, uint64_t need,
                            size_t have) {
  throw InputError(InputError::Kind::InvalidMesh, "mesh.data",
                   std::string("the ") + importFormatName(format) + " file declares " + what +
                       ", which need at least " + std::to_string(need) + " bytes; the file has " +
                       std::to_string(have));
}

// Vertices are counted before welding (a file may repeat a corner per face), hence the 8x.
void checkMeshCounts(uint64_t vertices, uint64_t faces, const MeshLimits& limits) {
  if (faces > static_cast<uint64_t>(limits.maxFaces)) {
    throw InputError(InputError::Kind::LimitExceeded, "maxFaces",
                     "the file declares " + std::to_string(faces) + " faces, more than " +
                         std::to_string(limits.maxFaces));
  }
  if (vertices > 8 * static_cast<uint64_t>(limits.maxVertices)) {
    throw InputError(InputError::Kind::LimitExceeded, "maxVertices",
                     "the file declares " + std::to_string(vertices) +
                         " vertices, more than 8 x " + std::to_string(limits.maxVertices));
  }
}

std::vector<std::string_view> words(std::string_view line) {
  std::vector<std::string_view> out;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    size_t j = i;
    while (j < line.size() && line[j] != ' ' && line[j] != '\t' && line[j] != '\r') ++j;
    if (j > i) out.push_back(line.substr(i, j - i));
    i = j;
  }
  return out;
}

std::optional<uint64_t> number(std::string_view text) {
  uint64_t value = 0;
  auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size()) return std::nullopt;
  return value;
}

size_t plyScalarBytes(std::string_view type) {
  if (type == "char" || type == "uchar" || type == "int8" || type == "uint8") return 1;
  if (type == "short" || type == "ushort" || type == "int16" || type == "uint16") return 2;
  if (type == "double" || type == "float64") return 8;
  return 4;  // int, uint, float and their sized names
}

// PLY: each element needs at least its properties' bytes (binary; a list at least its count)
// or two characters per property (ASCII: a digit and a separator).
void checkPly(std::string_view bytes, const MeshLimits& limits) {
  // Assimp 5.2's PLY reader loops forever on a header that never ends.
  const size_t end = bytes.find("end_header");
  if (bytes.substr(0, 3) != "ply" || end == std::string_view::npos) {
    throw InputError(InputError::Kind::InvalidMesh, "mesh.data",
                     "the ply file has no PLY header (\"ply\" ... \"end_header\")");
  }
  const size_t bodyStart = bytes.find('\n', end);
  const size_t body = bodyStart == std::string_view::npos ? 0 : bytes.size() - bodyStart - 1;
  bool ascii = false;
  uint64_t need = 0, vertices = 0, faces = 0, elementCount = 0, elementBytes = 0;
  std::string_view elementName;
  auto closeElement = [&] {
    need = plus(need, times(elementCount, std::max<uint64_t>(elementBytes, 1)));
    if (elementName == "vertex") vertices = elementCount;
    if (elementName == "face") faces = elementCount;
    elementCount = elementBytes = 0;
  };
  size_t at = 0;
  while (at < end) {
    size_t next = bytes.find('\n', at);
    if (next == std::string_view::npos || next > end) next = end;
    const std::vector<std::string_view> w = words(bytes.substr(at, next - at));
    at = next + 1;
    if (w.size() >= 2 && w[0] == "format") ascii = w[1] == "ascii";
    if (w.size() >= 3 && w[0] == "element") {
      closeElement();
      elementName = w[1];
      elementCount = number(w[2]).value_or(0);
    }
    if (w.size() >= 3 && w[0] == "property") {
      const bool list = w[1] == "list";
      elementBytes += ascii ? 2 : plyScalarBytes(list ? w[2] : w[1]);
    }
  }
  closeElement();
  checkMeshCounts(vertices, faces, limits);
  if (need > body) {
    dishonest(ImportFormat::Ply,
              std::to_string(vertices) + " vertices and " + std::to_string(faces) + " faces", need,
              body);
  }
}

// OFF: "OFF [nv nf ne]" then the counts; a vertex line is at least "0 0 0\n", a face line at
// least "3 0 1 2\n". Comment lines (#) are skipped.
void checkOff(std::string_view bytes, const MeshLimits& limits) {
  std::vector<std::string_view> tokens;
  size_t at = 0;
  while (at < bytes.size() && tokens.size() < 3) {
    size_t next = bytes.find('\n', at);
    if (next == std::string_view::npos) next = bytes.size();
    std::string_view line = bytes.substr(at, next - at);
    at = next + 1;
    if (const size_t hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
    for (std::string_view word : words(line)) {
      if (tokens.empty() && word.size() >= 3 && word.substr(word.size() - 3) == "OFF") {
        tokens.push_back(word);
      } else if (!tokens.empty()) {
        tokens.push_back(word);
      }
      if (tokens.size() == 3) break;
    }
  }
  if (tokens.size() < 3) return;
  const std::optional<uint64_t> vertices = number(tokens[1]), faces = number(tokens[2]);
  if (!vertices || !faces) return;
  checkMeshCounts(*vertices, *faces, limits);
  const uint64_t need = plus(times(*vertices, 6), times(*faces, 8));
  if (need > bytes.size()) {
    dishonest(ImportFormat::Off,
              std::to_string(*vertices) + " vertices and " + std::to_string(*faces) + " faces",
              need, bytes.size());
  }
}

uint32_t littleEndian32(const char* p) {
  uint32_t v;
  std::memcpy(&v, p, 4);
  return v;  // limn builds for little-endian machines only (as the worker protocol does)
}

bool startsWithSolid(std::string_view bytes) {
  size_t i = 0;
  while (i < bytes.size() && (bytes[i] == ' ' || bytes[i] == '\t')) ++i;
  return bytes.substr(i, 5) == "solid";
}

// Binary STL: an 80-byte header, the triangle count, then 50 bytes per triangle — exactly.
void checkStl(std::string_view bytes, const MeshLimits& limits) {
  if (bytes.size() >= 84) {
    const uint64_t triangles = littleEndian32(bytes.data() + 80);
    if (84 + 50 * triangles == bytes.size()) {
      checkMeshCounts(0, triangles, limits);
      return;
    }
  }
  if (startsWithSolid(bytes)) return;  // ASCII: read and counted as it goes
  const uint64_t triangles = bytes.size() >= 84 ? littleEndian32(bytes.data() + 80) : 0;
  dishonest(ImportFormat::Stl, "a binary STL of " + std::to_string(triangles) + " triangles",
            84 + 50 * triangles, bytes.size());
}

uint64_t gltfElementBytes(const rapidjson::Value& accessor) {
  uint64_t component = 4;
  if (accessor.HasMember("componentType") && accessor["componentType"].IsInt()) {
    const int type = accessor["componentType"].GetInt();
    component = (type == 5120 || type == 5121) ? 1 : (type == 5122 || type == 5123) ? 2 : 4;
  }
  uint64_t count = 1;
  if (accessor.HasMember("type") && accessor["type"].IsString()) {
    const std::string_view type = accessor["type"].GetString();
    count = type == "VEC2" ? 2 : type == "VEC3" ? 3 : type == "VEC4" || type == "MAT2" ? 4
            : type == "MAT3" ? 9 : type == "MAT4" ? 16 : 1;
  }
  return component * count;
}

// glTF: every buffer and every accessor's data must fit in the file (external files are never
// read, so everything lives in the file: GLB's binary chunk or data: URIs).
void checkGltf(std::string_view bytes, ImportFormat format) {
  std::string_view json = bytes;
  if (format == ImportFormat::Glb) {
    if (bytes.size() < 20 || bytes.substr(0, 4) != "glTF") return;
    const uint64_t length = littleEndian32(bytes.data() + 12);
    json = bytes.substr(20, std::min<uint64_t>(length, bytes.size() - 20));
  }
  rapidjson::Document document;
  document.Parse<rapidjson::kParseIterativeFlag>(json.data(), json.size());
  if (document.HasParseError() || !document.IsObject()) return;  // Assimp will say
  auto each = [&](const char* key, auto&& check) {
    if (!document.HasMember(key) || !document[key].IsArray()) return;
    const rapidjson::Value& array = document[key];
    for (rapidjson::SizeType i = 0; i < array.Size(); ++i) {
      if (array[i].IsObject()) check(array[i], i);
    }
  };
  each("buffers", [&](const rapidjson::Value& buffer, rapidjson::SizeType i) {
    if (buffer.HasMember("byteLength") && buffer["byteLength"].IsUint64() &&
        buffer["byteLength"].GetUint64() > bytes.size()) {
      dishonest(format, "buffer " + std::to_string(i) + " of " +
                            std::to_string(buffer["byteLength"].GetUint64()) + " bytes",
                buffer["byteLength"].GetUint64(), bytes.size());
    }
  });
  each("accessors", [&](const rapidjson::Value& accessor, rapidjson::SizeType i) {
    if (!accessor.HasMember("count") || !accessor["count"].IsUint64()) return;
    const uint64_t count = accessor["count"].GetUint64();
    const uint64_t need = times(count, gltfElementBytes(accessor));
    if (need > bytes.size()) {
      dishonest(format, "accessor " + std::to_string(i) + " of " + std::to_string(count) + " elements",
                need, bytes.size());
    }
  });
}

// COLLADA: an array's count="N" needs at least N characters.
void checkCollada(std::string_view bytes) {
  constexpr std::string_view kCount = "count=\"";
  for (size_t at = bytes.find(kCount); at != std::string_view::npos;
       at = bytes.find(kCount, at + 1)) {
    const size_t start = at + kCount.size();
    const size_t close = bytes.find('"', start);
    if (close == std::string_view::npos) return;
    const std::optional<uint64_t> count = number(bytes.substr(start, close - start));
    if (count && *count > bytes.size()) {
      dishonest(ImportFormat::Dae, "an array of " + std::to_string(*count) + " values", *count,
                bytes.size());
    }
  }
}

}  // namespace

void checkDeclaredSizes(std::string_view bytes, ImportFormat format, const MeshLimits& limits) {
  switch (format) {
    case ImportFormat::Ply: checkPly(bytes, limits); break;
    case ImportFormat::Off: checkOff(bytes, limits); break;
    case ImportFormat::Stl: checkStl(bytes, limits); break;
    case ImportFormat::Gltf:
    case ImportFormat::Glb: checkGltf(bytes, format); break;
    case ImportFormat::Dae: checkCollada(bytes); break;
    case ImportFormat::Fbx:
    case ImportFormat::ThreeDs: break;
  }
}

}  // namespace limn::formats
