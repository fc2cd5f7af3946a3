#include "formats/obj_reader.h"

#include <tiny_obj_loader.h>

#include <cstdlib>
#include <stdexcept>

#include "formats/obj_scan.h"
#include "render/core/error.h"
#include "render/core/quoted.h"

namespace limn::formats {

namespace {

using render::InputError;
using namespace render::mesh;

[[noreturn]] void badTag(const ObjTag& tag, const std::string& message) {
  std::string subject = "line " + std::to_string(tag.line);
  throw InputError(InputError::Kind::InvalidMesh, subject,
                   subject + ": tag " + render::quoted(tag.name) + " " + message);
}

std::string sizeTriple(const ObjTag& tag) {
  return std::to_string(tag.ints.size()) + "/" + std::to_string(tag.floats.size()) + "/" +
         std::to_string(tag.strings.size());
}

// One sharpness for all, or one per element.
float sharpnessOf(const ObjTag& tag, size_t element) {
  return static_cast<float>(tag.floats.size() == 1 ? tag.floats[0] : tag.floats[element]);
}

void applyTag(const ObjTag& tag, ObjMesh& out) {
  ControlMesh& mesh = out.mesh;
  const std::string& name = tag.name;
  if (name == "crease") {
    size_t pairs = tag.ints.size() / 2;
    if (tag.ints.size() < 2 || tag.ints.size() % 2 != 0 || !tag.strings.empty() ||
        (tag.floats.size() != 1 && tag.floats.size() != pairs)) {
      badTag(tag,
             "needs pairs of vertex indices and one sharpness for all or one per pair "
             "(2k/1/0 or 2k/k/0), got " +
                 sizeTriple(tag));
    }
    for (size_t p = 0; p < pairs; ++p) {
      mesh.creases.push_back({tag.ints[2 * p], tag.ints[2 * p + 1], sharpnessOf(tag, p)});
      out.creaseLines.push_back(tag.line);
    }
  } else if (name == "corner") {
    if (tag.ints.empty() || !tag.strings.empty() ||
        (tag.floats.size() != 1 && tag.floats.size() != tag.ints.size())) {
      badTag(tag,
             "needs vertex indices and one sharpness for all or one per vertex "
             "(n/1/0 or n/n/0), got " +
                 sizeTriple(tag));
    }
    for (size_t i = 0; i < tag.ints.size(); ++i) {
      mesh.corners.push_back({tag.ints[i], sharpnessOf(tag, i)});
      out.cornerLines.push_back(tag.line);
    }
  } else if (name == "hole") {
    if (tag.ints.empty() || !tag.floats.empty() || !tag.strings.empty()) {
      badTag(tag, "needs face indices only (n/0/0), got " + sizeTriple(tag));
    }
    for (int face : tag.ints) {
      mesh.holes.push_back(face);
      out.holeLines.push_back(tag.line);
    }
  } else if (name == "interpolateboundary") {
    if (tag.ints.size() != 1 || !tag.floats.empty() || !tag.strings.empty() || tag.ints[0] < 0 ||
        tag.ints[0] > 2) {
      badTag(tag, "needs one integer: 0 none, 1 edge-and-corner, 2 edge-only (1/0/0)");
    }
    const BoundaryInterpolation rules[] = {BoundaryInterpolation::None,
                                           BoundaryInterpolation::EdgeAndCorner,
                                           BoundaryInterpolation::EdgeOnly};
    mesh.boundary = rules[tag.ints[0]];
  } else if (name == "creasemethod") {
    std::string value = tag.strings.size() == 1 ? tag.strings[0] : "";
    if (!tag.ints.empty() || !tag.floats.empty() ||
        (value != "chaikin" && value != "normal" && value != "uniform")) {
      badTag(tag, "needs one string: chaikin or normal (0/0/1)");
    }
    mesh.creaseMethod = value == "chaikin" ? CreaseMethod::Chaikin : CreaseMethod::Uniform;
  } else if (name == "smoothtriangles") {
    std::string value = tag.strings.size() == 1 ? tag.strings[0] : "";
    if (!tag.ints.empty() || !tag.floats.empty() ||
        (value != "smooth" && value != "catmark" && value != "catmull-clark")) {
      badTag(tag, "needs one string: smooth or catmark (0/0/1)");
    }
    mesh.triangleSubdivision =
        value == "smooth" ? TriangleSubdivision::Smooth : TriangleSubdivision::CatmullClark;
  } else {
    out.warnings.push_back("line " + std::to_string(tag.line) + ": tag " + render::quoted(name) +
                           " is not supported and was ignored");
  }
}

// "face 12" -> {"face", 12}; anything else -> {"", -1}.
std::pair<std::string, long> splitSubject(const std::string& subject) {
  size_t space = subject.find(' ');
  if (space == std::string::npos || space + 1 >= subject.size()) return {"", -1};
  char* end = nullptr;
  long index = std::strtol(subject.c_str() + space + 1, &end, 10);
  if (*end != '\0' || index < 0) return {"", -1};
  return {subject.substr(0, space), index};
}

}  // namespace

void validateObjMesh(const ObjMesh& obj, const MeshLimits& limits) {
  try {
    validateMesh(obj.mesh, limits);
  } catch (const InputError& error) {
    auto [kind, index] = splitSubject(error.subject());
    const std::vector<int>* lines = kind == "vertex"   ? &obj.vertexLines
                                    : kind == "face"   ? &obj.faceLines
                                    : kind == "crease" ? &obj.creaseLines
                                    : kind == "corner" ? &obj.cornerLines
                                    : kind == "hole"   ? &obj.holeLines
                                                       : nullptr;
    if (!lines || index >= static_cast<long>(lines->size())) throw;
    throw InputError(
        error.kind(), error.subject(),
        std::string(error.what()) + " (OBJ line " + std::to_string((*lines)[index]) + ")");
  }
}

ObjMesh readObj(std::string_view text, Scheme scheme, const MeshLimits& limits) {
  ObjMesh obj = parseObj(text, scheme, limits);
  validateObjMesh(obj, limits);
  return obj;
}

ObjMesh parseObj(std::string_view text, Scheme scheme, const MeshLimits& limits) {
  ObjScan scan = scanObj(text, limits);

  tinyobj::ObjReaderConfig config;
  config.triangulate = false;
  config.vertex_color = false;
  tinyobj::ObjReader reader;
  if (!reader.ParseFromString(std::string(text), std::string(), config)) {
    std::string message = reader.Error();
    while (!message.empty() && (message.back() == '\n' || message.back() == ' ')) {
      message.pop_back();
    }
    throw InputError(InputError::Kind::InvalidMesh, "obj",
                     "the OBJ text could not be read: " + message);
  }

  ObjMesh out;
  ControlMesh& mesh = out.mesh;
  mesh.scheme = scheme;
  mesh.boundary = BoundaryInterpolation::EdgeOnly;
  out.warnings = std::move(scan.warnings);
  out.vertexLines = std::move(scan.vertexLines);
  out.faceLines = std::move(scan.faceLines);

  const tinyobj::attrib_t& attrib = reader.GetAttrib();
  // The scan accepted exactly what tinyobjloader reads; a disagreement is a bug, not bad input.
  if (attrib.vertices.size() != out.vertexLines.size() * 3) {
    throw std::logic_error("OBJ reader: tinyobjloader read " +
                           std::to_string(attrib.vertices.size() / 3) + " vertices, the scan " +
                           std::to_string(out.vertexLines.size()));
  }
  mesh.points.reserve(out.vertexLines.size());
  for (size_t i = 0; i + 2 < attrib.vertices.size(); i += 3) {
    mesh.points.push_back({attrib.vertices[i], attrib.vertices[i + 1], attrib.vertices[i + 2]});
  }

  // Faces of all shapes (groups, objects, material runs) in file order; indices are global.
  for (const tinyobj::shape_t& shape : reader.GetShapes()) {
    size_t offset = 0;
    for (unsigned char count : shape.mesh.num_face_vertices) {
      const int face = mesh.faceCount();
      mesh.faceVertexCounts.push_back(count);
      for (size_t k = 0; k < count; ++k) {
        int v = shape.mesh.indices[offset + k].vertex_index;
        if (face < static_cast<int>(out.faceLines.size()) && (v < 0 || v >= mesh.vertexCount())) {
          std::string subject = "face " + std::to_string(face);
          throw InputError(InputError::Kind::InvalidMesh, subject,
                           "line " + std::to_string(out.faceLines[face]) + ": " + subject +
                               " uses vertex " + std::to_string(v + 1) + " but the file has only " +
                               std::to_string(mesh.vertexCount()) +
                               " vertices (OBJ indices start at 1)");
        }
        mesh.faceVertexIndices.push_back(v);
      }
      offset += count;
    }
  }
  if (mesh.faceVertexCounts.size() != out.faceLines.size()) {
    throw std::logic_error("OBJ reader: tinyobjloader read " +
                           std::to_string(mesh.faceVertexCounts.size()) + " faces, the scan " +
                           std::to_string(out.faceLines.size()));
  }

  for (const ObjTag& tag : scan.tags) applyTag(tag, out);
  return out;
}

}  // namespace limn::formats
