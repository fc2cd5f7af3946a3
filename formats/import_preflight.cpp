#include "formats/import_preflight.h"

#include <rapidjson/document.h>

#include <charconv>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <utility>
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
                     "the file declares " + std::to_string(vertices) + " vertices, more than 8 x " +
                         std::to_string(limits.maxVertices));
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

// The scalar types of PLY (both spellings) and their sizes; 0: not a PLY type.
size_t plyScalarBytes(std::string_view type) {
  static const std::pair<std::string_view, size_t> kTypes[] = {
      {"char", 1},  {"uchar", 1},   {"int8", 1},   {"uint8", 1},   {"short", 2}, {"ushort", 2},
      {"int16", 2}, {"uint16", 2},  {"int", 4},    {"uint", 4},    {"int32", 4}, {"uint32", 4},
      {"float", 4}, {"float32", 4}, {"double", 8}, {"float64", 8},
  };
  for (const auto& [name, size] : kTypes) {
    if (type == name) return size;
  }
  return 0;
}

[[noreturn]] void badPlyHeader(int line, const std::string& why) {
  throw InputError(InputError::Kind::InvalidMesh, "mesh.data",
                   "the ply file's header line " + std::to_string(line) + " " + why);
}

bool printable(std::string_view line) {
  for (unsigned char c : line) {
    if ((c < 0x20 && c != '\t' && c != '\r') || c == 0x7F) return false;
  }
  return true;
}

// PLY: the header is checked line by line against the grammar (Assimp 5.2's PLY reader loops
// forever on a header that never ends and reads out of bounds on some malformed property
// lines: both found by fuzz/mesh_import), then each element needs at least its properties'
// bytes (binary; a list at least its count) or two characters per property (ASCII: a digit and
// a separator).
void checkPly(std::string_view bytes, const MeshLimits& limits) {
  bool ascii = false, formatSeen = false, ended = false, inElement = false;
  uint64_t need = 0, vertices = 0, faces = 0, elementCount = 0, elementBytes = 0;
  std::string_view elementName;
  auto closeElement = [&] {
    if (!inElement) return;
    need = plus(need, times(elementCount, std::max<uint64_t>(elementBytes, 1)));
    if (elementName == "vertex") vertices = elementCount;
    if (elementName == "face") faces = elementCount;
    elementCount = elementBytes = 0;
  };
  size_t at = 0;
  int line = 0;
  while (at < bytes.size() && !ended) {
    size_t next = bytes.find('\n', at);
    if (next == std::string_view::npos) next = bytes.size();
    const std::string_view text = bytes.substr(at, next - at);
    at = next + 1;
    ++line;
    if (!printable(text)) badPlyHeader(line, "holds control characters");
    const std::vector<std::string_view> w = words(text);
    if (line == 1) {
      if (w.size() != 1 || w[0] != "ply") badPlyHeader(line, "is not \"ply\"");
      continue;
    }
    if (w.empty()) badPlyHeader(line, "is empty");
    if (w[0] == "comment" || w[0] == "obj_info") continue;
    if (w[0] == "end_header" && w.size() == 1) {
      ended = true;
    } else if (w[0] == "format") {
      if (formatSeen || inElement || w.size() != 3 || w[2] != "1.0" ||
          (w[1] != "ascii" && w[1] != "binary_little_endian" && w[1] != "binary_big_endian")) {
        badPlyHeader(line, "is not one format line before the elements (format ascii 1.0, ...)");
      }
      formatSeen = true;
      ascii = w[1] == "ascii";
    } else if (w[0] == "element") {
      const std::optional<uint64_t> count = w.size() == 3 ? number(w[2]) : std::nullopt;
      if (!count) badPlyHeader(line, "is not \"element NAME COUNT\"");
      closeElement();
      inElement = true;
      elementName = w[1];
      elementCount = *count;
    } else if (w[0] == "property") {
      const bool list = w.size() == 5 && w[1] == "list";
      const bool typed = list ? plyScalarBytes(w[2]) > 0 && plyScalarBytes(w[3]) > 0
                              : w.size() == 3 && plyScalarBytes(w[1]) > 0;
      if (!inElement || !typed) {
        badPlyHeader(line,
                     "is not \"property TYPE NAME\" or \"property list TYPE TYPE NAME\" "
                     "of an element");
      }
      elementBytes += ascii ? 2 : plyScalarBytes(list ? w[2] : w[1]);
    } else {
      badPlyHeader(line, "is not a PLY header line");
    }
  }
  if (!ended || !formatSeen) {
    throw InputError(InputError::Kind::InvalidMesh, "mesh.data",
                     "the ply file has no complete PLY header (\"ply\", \"format ...\", "
                     "elements, \"end_header\")");
  }
  closeElement();
  checkMeshCounts(vertices, faces, limits);
  const uint64_t body = bytes.size() - std::min(at, bytes.size());
  if (need > body) {
    dishonest(ImportFormat::Ply,
              std::to_string(vertices) + " vertices and " + std::to_string(faces) + " faces", need,
              body);
  }
}

// OFF: a header line ("OFF", or a variant such as "COFF", "NOFF") alone, then the line of counts
// "nv nf [ne]" in decimal — nothing else, since Assimp reads the counts with a lenient prefix
// parse (fuzz/mesh_import found "OFF 6" then "802384185579,0.6" allocating 46 GB). A vertex
// line is at least "0 0 0\n", a face line at least "3 0 1 2\n". Comment lines (#) are skipped.
void checkOff(std::string_view bytes, const MeshLimits& limits) {
  std::vector<std::vector<std::string_view>> lines;  // the first two that are not comments
  size_t at = 0;
  while (at < bytes.size() && lines.size() < 2) {
    size_t next = bytes.find('\n', at);
    if (next == std::string_view::npos) next = bytes.size();
    std::string_view line = bytes.substr(at, next - at);
    at = next + 1;
    if (const size_t hash = line.find('#'); hash != std::string_view::npos)
      line = line.substr(0, hash);
    std::vector<std::string_view> w = words(line);
    if (!w.empty()) lines.push_back(std::move(w));
  }
  const bool header = lines.size() == 2 && lines[0].size() == 1 && lines[0][0].size() >= 3 &&
                      lines[0][0].substr(lines[0][0].size() - 3) == "OFF";
  const bool countLine = header && (lines[1].size() == 2 || lines[1].size() == 3) &&
                         number(lines[1][0]) && number(lines[1][1]) &&
                         (lines[1].size() == 2 || number(lines[1][2]));
  if (!countLine) {
    throw InputError(InputError::Kind::InvalidMesh, "mesh.data",
                     "the off file does not start with an OFF line and then the line of counts "
                     "\"vertices faces [edges]\"");
  }
  const uint64_t vertices = *number(lines[1][0]), faces = *number(lines[1][1]);
  checkMeshCounts(vertices, faces, limits);
  const uint64_t need = plus(times(vertices, 6), times(faces, 8));
  if (need > bytes.size()) {
    dishonest(ImportFormat::Off,
              std::to_string(vertices) + " vertices and " + std::to_string(faces) + " faces", need,
              bytes.size());
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
    count = type == "VEC2"                     ? 2
            : type == "VEC3"                   ? 3
            : type == "VEC4" || type == "MAT2" ? 4
            : type == "MAT3"                   ? 9
            : type == "MAT4"                   ? 16
                                               : 1;
  }
  return component * count;
}

// glTF: every buffer and every accessor's data must fit in the file (external files are never
// read, so everything lives in the file: GLB's binary chunk or data: URIs).
void checkGltf(std::string_view bytes, ImportFormat format) {
  std::string_view json = bytes;
  if (format == ImportFormat::Glb) {
    if (bytes.size() < 20 || bytes.substr(0, 4) != "glTF") return;  // Assimp will say
    // The header's total and each chunk's length (Assimp allocates what they say).
    const uint64_t total = littleEndian32(bytes.data() + 8);
    if (total > bytes.size())
      dishonest(format, "a GLB of " + std::to_string(total) + " bytes", total, bytes.size());
    for (uint64_t at = 12; at + 8 <= bytes.size();) {
      const uint64_t chunk = littleEndian32(bytes.data() + at);
      if (at + 8 + chunk > bytes.size()) {
        dishonest(format, "a chunk of " + std::to_string(chunk) + " bytes", at + 8 + chunk,
                  bytes.size());
      }
      at += 8 + chunk;
    }
    json = bytes.substr(20, littleEndian32(bytes.data() + 12));
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
      dishonest(format,
                "buffer " + std::to_string(i) + " of " +
                    std::to_string(buffer["byteLength"].GetUint64()) + " bytes",
                buffer["byteLength"].GetUint64(), bytes.size());
    }
  });
  each("accessors", [&](const rapidjson::Value& accessor, rapidjson::SizeType i) {
    if (!accessor.HasMember("count") || !accessor["count"].IsUint64()) return;
    const uint64_t count = accessor["count"].GetUint64();
    const uint64_t need = times(count, gltfElementBytes(accessor));
    if (need > bytes.size()) {
      dishonest(format,
                "accessor " + std::to_string(i) + " of " + std::to_string(count) + " elements",
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
    case ImportFormat::Ply:
      checkPly(bytes, limits);
      break;
    case ImportFormat::Off:
      checkOff(bytes, limits);
      break;
    case ImportFormat::Stl:
      checkStl(bytes, limits);
      break;
    case ImportFormat::Gltf:
    case ImportFormat::Glb:
      checkGltf(bytes, format);
      break;
    case ImportFormat::Dae:
      checkCollada(bytes);
      break;
    case ImportFormat::Fbx:
    case ImportFormat::ThreeDs:
      break;
  }
}

}  // namespace limn::formats
