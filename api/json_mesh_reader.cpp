#include "api/json_mesh_reader.h"

#include "api/json_util.h"
#include "render/core/error.h"

namespace limn::api {

namespace {

using render::InputError;
using namespace render::mesh;

std::string at(const std::string& field, size_t i) { return field + "[" + std::to_string(i) + "]"; }

std::vector<int> intArray(const json::Value& object, const std::string& field, const char* name,
                          bool required) {
  std::vector<int> out;
  const json::Value* value = json::find(object, name);
  std::string path = field + "." + name;
  if (!value) {
    if (required) json::fail(path, path + " is required");
    return out;
  }
  json::requireArray(*value, path);
  out.reserve(value->Size());
  for (rapidjson::SizeType i = 0; i < value->Size(); ++i) {
    out.push_back(json::integer((*value)[i], at(path, i)));
  }
  return out;
}

std::vector<float> floatArray(const json::Value& object, const std::string& field,
                              const char* name) {
  std::vector<float> out;
  const json::Value* value = json::find(object, name);
  if (!value) return out;
  std::string path = field + "." + name;
  json::requireArray(*value, path);
  for (rapidjson::SizeType i = 0; i < value->Size(); ++i) {
    out.push_back(static_cast<float>(json::number((*value)[i], at(path, i))));
  }
  return out;
}

[[noreturn]] void invalid(const std::string& subject, const std::string& message) {
  throw InputError(InputError::Kind::InvalidMesh, subject, message);
}

void readPoints(const json::Value& object, const std::string& field, const MeshLimits& limits,
                ControlMesh& mesh) {
  std::string path = field + ".points";
  const json::Value* points = json::find(object, "points");
  if (!points) json::fail(path, path + " is required");
  json::requireArray(*points, path);
  if (static_cast<long>(points->Size()) > limits.maxVertices) {
    throw InputError(InputError::Kind::LimitExceeded, "maxVertices",
                     "mesh exceeds limit maxVertices: " + std::to_string(points->Size()) + " > " +
                         std::to_string(limits.maxVertices));
  }
  mesh.points.reserve(points->Size());
  for (rapidjson::SizeType i = 0; i < points->Size(); ++i) {
    mesh.points.push_back(json::vec3((*points)[i], at(path, i)));
  }
}

void readCreases(const json::Value& object, const std::string& field, ControlMesh& mesh) {
  std::vector<int> indices = intArray(object, field, "creaseIndices", false);
  std::vector<int> lengths = intArray(object, field, "creaseLengths", false);
  std::vector<float> sharpnesses = floatArray(object, field, "creaseSharpnesses");
  if (indices.empty() && lengths.empty() && sharpnesses.empty()) return;
  if (lengths.empty()) {
    json::fail(field + ".creaseLengths",
               field + ".creaseLengths is required with creaseIndices (one length per crease)");
  }
  size_t total = 0, edges = 0;
  for (size_t c = 0; c < lengths.size(); ++c) {
    if (lengths[c] < 2) {
      invalid("crease " + std::to_string(c), "creaseLengths[" + std::to_string(c) + "] is " +
                                                 std::to_string(lengths[c]) +
                                                 ": a crease is a chain of at least 2 vertices");
    }
    total += lengths[c];
    edges += lengths[c] - 1;
  }
  if (total != indices.size()) {
    invalid("creaseLengths", "creaseLengths sums to " + std::to_string(total) +
                                 " but creaseIndices has " + std::to_string(indices.size()) +
                                 " entries");
  }
  bool perEdge = sharpnesses.size() == edges;
  if (sharpnesses.size() != lengths.size() && !perEdge) {
    invalid("creaseSharpnesses", "creaseSharpnesses has " + std::to_string(sharpnesses.size()) +
                                     " values: give one per crease (" +
                                     std::to_string(lengths.size()) + ") or one per edge (" +
                                     std::to_string(edges) + ")");
  }
  size_t start = 0, edge = 0;
  for (size_t c = 0; c < lengths.size(); ++c) {
    for (int k = 0; k + 1 < lengths[c]; ++k, ++edge) {
      float s = perEdge ? sharpnesses[edge] : sharpnesses[c];
      mesh.creases.push_back({indices[start + k], indices[start + k + 1], s});
    }
    start += lengths[c];
  }
}

void readCorners(const json::Value& object, const std::string& field, ControlMesh& mesh) {
  std::vector<int> indices = intArray(object, field, "cornerIndices", false);
  std::vector<float> sharpnesses = floatArray(object, field, "cornerSharpnesses");
  if (indices.size() != sharpnesses.size()) {
    invalid("cornerSharpnesses", "cornerIndices has " + std::to_string(indices.size()) +
                                     " entries but cornerSharpnesses has " +
                                     std::to_string(sharpnesses.size()) +
                                     ": give one sharpness per corner");
  }
  for (size_t i = 0; i < indices.size(); ++i) mesh.corners.push_back({indices[i], sharpnesses[i]});
}

}  // namespace

Scheme readScheme(const json::Value& value, const std::string& field) {
  return json::choice<Scheme>(value, field,
                              {{"catmull-clark", Scheme::CatmullClark},
                               {"loop", Scheme::Loop},
                               {"bilinear", Scheme::Bilinear},
                               {"catmullClark", Scheme::CatmullClark}});
}

ControlMesh readJsonMesh(const json::Value& object, const std::string& field,
                         const MeshLimits& limits) {
  json::requireObject(object, field);
  ControlMesh mesh;
  if (const json::Value* v = json::find(object, "scheme")) {
    mesh.scheme = readScheme(*v, field + ".scheme");
  }
  readPoints(object, field, limits, mesh);
  mesh.faceVertexCounts = intArray(object, field, "faceVertexCounts", true);
  if (static_cast<long>(mesh.faceVertexCounts.size()) > limits.maxFaces) {
    throw InputError(
        InputError::Kind::LimitExceeded, "maxFaces",
        "mesh exceeds limit maxFaces: " + std::to_string(mesh.faceVertexCounts.size()) + " > " +
            std::to_string(limits.maxFaces));
  }
  mesh.faceVertexIndices = intArray(object, field, "faceVertexIndices", true);
  readCreases(object, field, mesh);
  readCorners(object, field, mesh);
  mesh.holes = intArray(object, field, "holeIndices", false);

  if (const json::Value* v = json::find(object, "interpolateBoundary")) {
    mesh.boundary = json::choice<BoundaryInterpolation>(
        *v, field + ".interpolateBoundary",
        {{"none", BoundaryInterpolation::None},
         {"edge-only", BoundaryInterpolation::EdgeOnly},
         {"edge-and-corner", BoundaryInterpolation::EdgeAndCorner},
         {"edgeOnly", BoundaryInterpolation::EdgeOnly},
         {"edgeAndCorner", BoundaryInterpolation::EdgeAndCorner}});
  }
  if (const json::Value* v = json::find(object, "creaseMethod")) {
    mesh.creaseMethod = json::choice<CreaseMethod>(
        *v, field + ".creaseMethod",
        {{"uniform", CreaseMethod::Uniform}, {"chaikin", CreaseMethod::Chaikin}});
  }
  if (const json::Value* v = json::find(object, "triangleSubdivision")) {
    mesh.triangleSubdivision =
        json::choice<TriangleSubdivision>(*v, field + ".triangleSubdivision",
                                          {{"catmull-clark", TriangleSubdivision::CatmullClark},
                                           {"smooth", TriangleSubdivision::Smooth},
                                           {"catmullClark", TriangleSubdivision::CatmullClark}});
  }
  validateMesh(mesh, limits);
  return mesh;
}

std::string writeJsonMesh(const ControlMesh& mesh) {
  rapidjson::StringBuffer buffer;
  json::Writer w(buffer);
  auto ints = [&](const char* key, auto count, auto value) {
    w.Key(key);
    w.StartArray();
    for (size_t i = 0; i < static_cast<size_t>(count); ++i) w.Int(value(i));
    w.EndArray();
  };
  auto numbers = [&](const char* key, auto count, auto value) {
    w.Key(key);
    w.StartArray();
    for (size_t i = 0; i < static_cast<size_t>(count); ++i) json::writeNumber(w, value(i));
    w.EndArray();
  };
  w.StartObject();
  w.Key("format");
  w.String("json");
  w.Key("scheme");
  w.String(mesh.scheme == Scheme::Loop       ? "loop"
           : mesh.scheme == Scheme::Bilinear ? "bilinear"
                                             : "catmull-clark");
  w.Key("points");
  w.StartArray();
  for (const auto& p : mesh.points) {
    w.StartArray();
    for (int k = 0; k < 3; ++k) json::writeNumber(w, p[k]);
    w.EndArray();
  }
  w.EndArray();
  ints("faceVertexCounts", mesh.faceVertexCounts.size(),
       [&](size_t i) { return mesh.faceVertexCounts[i]; });
  ints("faceVertexIndices", mesh.faceVertexIndices.size(),
       [&](size_t i) { return mesh.faceVertexIndices[i]; });
  if (!mesh.creases.empty()) {
    ints("creaseIndices", 2 * mesh.creases.size(),
         [&](size_t i) { return i % 2 ? mesh.creases[i / 2].v1 : mesh.creases[i / 2].v0; });
    ints("creaseLengths", mesh.creases.size(), [](size_t) { return 2; });
    numbers("creaseSharpnesses", mesh.creases.size(),
            [&](size_t i) { return mesh.creases[i].sharpness; });
  }
  if (!mesh.corners.empty()) {
    ints("cornerIndices", mesh.corners.size(), [&](size_t i) { return mesh.corners[i].vertex; });
    numbers("cornerSharpnesses", mesh.corners.size(),
            [&](size_t i) { return mesh.corners[i].sharpness; });
  }
  if (!mesh.holes.empty()) {
    ints("holeIndices", mesh.holes.size(), [&](size_t i) { return mesh.holes[i]; });
  }
  w.Key("interpolateBoundary");
  w.String(mesh.boundary == BoundaryInterpolation::None       ? "none"
           : mesh.boundary == BoundaryInterpolation::EdgeOnly ? "edge-only"
                                                              : "edge-and-corner");
  w.Key("creaseMethod");
  w.String(mesh.creaseMethod == CreaseMethod::Chaikin ? "chaikin" : "uniform");
  w.Key("triangleSubdivision");
  w.String(mesh.triangleSubdivision == TriangleSubdivision::Smooth ? "smooth" : "catmull-clark");
  w.EndObject();
  return {buffer.GetString(), buffer.GetSize()};
}

}  // namespace limn::api
