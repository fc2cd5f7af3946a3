// parseRenderRequest: the JSON body of POST /v1/render -> RenderRequest, checked against the
// job limits. Cheap fields first, the mesh last, so that an over-limit image size is refused
// without reading a large mesh.
#include <rapidjson/error/en.h>

#include <cmath>
#include <initializer_list>
#include <set>

#include "api/base64.h"
#include "api/json_mesh_reader.h"
#include "api/json_util.h"
#include "api/render_api.h"
#include "api/request_parts.h"
#include "formats/assimp_import.h"
#include "formats/obj_reader.h"
#include "render/mesh/mesh_cache.h"

namespace limn::api {

namespace {

using json::Value;
using render::pipeline::JobLimits;
using render::pipeline::Method;

void warnUnknownFields(const Value& object, const std::string& prefix,
                       std::initializer_list<const char*> known,
                       std::vector<std::string>& warnings) {
  for (auto it = object.MemberBegin(); it != object.MemberEnd(); ++it) {
    std::string_view name(it->name.GetString(), it->name.GetStringLength());
    bool isKnown = false;
    for (const char* k : known) isKnown = isKnown || name == k;
    if (!isKnown) {
      warnings.push_back(
          "ignored unknown field " +
          json::quote(prefix.empty() ? std::string(name) : prefix + "." + std::string(name)));
    }
  }
}

Method parseMethod(const Value& value) {
  return json::choice<Method>(value, "method",
                              {{"coarse", Method::Coarse},
                               {"uniform", Method::Uniform},
                               {"adaptive", Method::Adaptive},
                               {"limit", Method::Limit},
                               {"silhouette", Method::Silhouette},
                               {"patches", Method::Patches}});
}

// params of the silhouette method (read whatever the method; they only matter to it).
void parseSilhouetteParams(const Value& params, const JobLimits& limits,
                           render::pipeline::MethodParams& out) {
  using render::silhouette::Presubdivide;
  if (const Value* v = json::find(params, "presubdivide")) {
    if (v->IsString() && std::string_view(v->GetString()) == "auto") {
      out.presubdivide = Presubdivide::Auto;
    } else if (v->IsInt() && (v->GetInt() == 0 || v->GetInt() == 1)) {
      out.presubdivide = v->GetInt() == 0 ? Presubdivide::Never : Presubdivide::Once;
    } else {
      json::fail("params.presubdivide",
                 "params.presubdivide must be \"auto\", 0 or 1; got " + json::describe(*v));
    }
  }
  auto boundedInt = [&](const char* name, int& field, int lo, int hi, const char* limitName) {
    const Value* v = json::find(params, name);
    if (!v) return;
    std::string path = std::string("params.") + name;
    field = json::integer(*v, path);
    if (field < lo) json::fail(path, path + " must be >= " + std::to_string(lo));
    if (field > hi) {
      throw tooLarge(limitName, path,
                     path + " " + std::to_string(field) + " exceeds limit " + limitName + " (" +
                         std::to_string(hi) + ")");
    }
  };
  boundedInt("searchSteps", out.searchSteps, 0, limits.maxSearchSteps, "maxSearchSteps");
  boundedInt("curveSamples", out.curveSamples, 0, limits.maxCurveSamples, "maxCurveSamples");
  if (const Value* v = json::find(params, "contour")) {
    out.contour = json::choice<render::silhouette::CurveMode>(
        *v, "params.contour",
        {{"exact", render::silhouette::CurveMode::Exact},
         {"pn", render::silhouette::CurveMode::PN}});
  }
}

render::pipeline::MethodParams parseParams(const Value& params, const JobLimits& limits,
                                           std::vector<std::string>& warnings) {
  json::requireObject(params, "params");
  warnUnknownFields(params, "params",
                    {"level", "engine", "pushToLimit", "dicingRate", "metricSupersample",
                     "referenceCrossCheck", "presubdivide", "searchSteps", "curveSamples",
                     "contour", "isolation", "cullPatches", "tessellator", "retessellateFrames"},
                    warnings);
  render::pipeline::MethodParams out;
  if (const Value* v = json::find(params, "level")) {
    out.level = json::integer(*v, "params.level");
    if (out.level < 0) json::fail("params.level", "params.level must be >= 0");
    if (out.level > limits.maxLevel) {
      throw tooLarge("maxLevel", "params.level",
                     "params.level " + std::to_string(out.level) + " exceeds limit maxLevel (" +
                         std::to_string(limits.maxLevel) + ")");
    }
  }
  if (const Value* v = json::find(params, "engine")) {
    using render::pipeline::Engine;
    out.engine = json::choice<Engine>(*v, "params.engine",
                                      {{"auto", Engine::Auto},
                                       {"opensubdiv", Engine::OpenSubdiv},
                                       {"masks", Engine::Masks},
                                       {"factored", Engine::Factored}});
  }
  if (const Value* v = json::find(params, "pushToLimit")) {
    out.pushToLimit = json::boolean(*v, "params.pushToLimit");
  }
  if (const Value* v = json::find(params, "dicingRate")) {
    out.dicingRate = json::number(*v, "params.dicingRate");
    if (!(out.dicingRate > 0)) json::fail("params.dicingRate", "params.dicingRate must be > 0");
    if (out.dicingRate < limits.minDicingRate) {
      throw tooLarge("minDicingRate", "params.dicingRate",
                     "params.dicingRate " + json::formatNumber(out.dicingRate) +
                         " is below limit minDicingRate (" +
                         json::formatNumber(limits.minDicingRate) + " pixels)");
    }
  }
  if (const Value* v = json::find(params, "isolation")) {
    out.isolation = json::integer(*v, "params.isolation");
    if (out.isolation < 1) json::fail("params.isolation", "params.isolation must be >= 1");
    if (out.isolation > limits.maxIsolation) {
      throw tooLarge("maxIsolation", "params.isolation",
                     "params.isolation " + std::to_string(out.isolation) +
                         " exceeds limit maxIsolation (" + std::to_string(limits.maxIsolation) +
                         ")");
    }
  }
  if (const Value* v = json::find(params, "retessellateFrames")) {
    out.retessellateFrames = json::boolean(*v, "params.retessellateFrames");
  }
  if (const Value* v = json::find(params, "cullPatches")) {
    out.cullPatches = json::boolean(*v, "params.cullPatches");
  }
  if (const Value* v = json::find(params, "tessellator")) {
    using render::pipeline::PatchTessellator;
    out.tessellator = json::choice<PatchTessellator>(
        *v, "params.tessellator", {{"cpu", PatchTessellator::Cpu}, {"gpu", PatchTessellator::Gpu}});
  }
  if (const Value* v = json::find(params, "referenceCrossCheck")) {
    out.referenceCrossCheck = json::boolean(*v, "params.referenceCrossCheck");
  }
  if (const Value* v = json::find(params, "metricSupersample")) {
    out.metricSupersample = json::integer(*v, "params.metricSupersample");
    if (out.metricSupersample < 1) {
      json::fail("params.metricSupersample", "params.metricSupersample must be >= 1");
    }
    if (out.metricSupersample > limits.maxSupersample) {
      throw tooLarge("maxSupersample", "params.metricSupersample",
                     "params.metricSupersample " + std::to_string(out.metricSupersample) +
                         " exceeds limit maxSupersample (" + std::to_string(limits.maxSupersample) +
                         ")");
    }
  }
  parseSilhouetteParams(params, limits, out);
  return out;
}

// `animation` (set when the list has "turntable"): /v1/render's outputs; null: the others'.
render::pipeline::Outputs readOutputs(const Value& value, bool* animation = nullptr) {
  json::requireArray(value, "outputs");
  render::pipeline::Outputs out;
  out.color = false;
  enum Pass { Color, Mask, Depth, Normal, Wireframe, Contours, Cage, Diff, Patches };
  for (rapidjson::SizeType i = 0; i < value.Size(); ++i) {
    if (animation && value[i].IsString() && std::string_view(value[i].GetString()) == "turntable") {
      *animation = true;
      continue;
    }
    Pass pass = json::choice<Pass>(value[i], "outputs[" + std::to_string(i) + "]",
                                   {{"color", Color},
                                    {"mask", Mask},
                                    {"depth", Depth},
                                    {"normal", Normal},
                                    {"wireframe", Wireframe},
                                    {"contours", Contours},
                                    {"cage", Cage},
                                    {"diff", Diff},
                                    {"patches", Patches}});
    bool* flags[] = {&out.color,    &out.mask, &out.depth, &out.normal, &out.wireframe,
                     &out.contours, &out.cage, &out.diff,  &out.patches};
    *flags[pass] = true;
  }
  return out;
}

// "frames": [[[x, y, z], ...], ...]: the control points of each animation frame.
std::vector<std::vector<render::Vec3>> readFrames(const Value& value,
                                                  const render::pipeline::RenderJob& job,
                                                  const JobLimits& limits) {
  json::requireArray(value, "frames");
  if (job.method != Method::Patches) {
    json::fail("frames", "frames are drawn by method \"patches\" only");
  }
  if (value.Size() == 0) json::fail("frames", "frames must hold at least one frame");
  if (value.Size() > limits.maxFrames) {
    throw tooLarge("maxFrames", "frames",
                   "frames: " + std::to_string(value.Size()) + " exceed limit maxFrames (" +
                       std::to_string(limits.maxFrames) + ")");
  }
  std::vector<std::vector<render::Vec3>> frames(value.Size());
  for (rapidjson::SizeType f = 0; f < value.Size(); ++f) {
    const std::string field = "frames[" + std::to_string(f) + "]";
    json::requireArray(value[f], field);
    if (value[f].Size() != job.mesh.points.size()) {
      json::fail(field, field + " has " + std::to_string(value[f].Size()) +
                            " points; the mesh has " + std::to_string(job.mesh.points.size()));
    }
    frames[f].reserve(value[f].Size());
    for (rapidjson::SizeType i = 0; i < value[f].Size(); ++i) {
      frames[f].push_back(json::vec3(value[f][i], field + "[" + std::to_string(i) + "]"));
    }
  }
  return frames;
}

// {"id": "..."}: a mesh uploaded before with POST /v1/meshes.
render::mesh::ControlMesh storedMesh(const Value& mesh, render::mesh::MeshCache* meshes) {
  for (auto it = mesh.MemberBegin(); it != mesh.MemberEnd(); ++it) {
    std::string_view name(it->name.GetString(), it->name.GetStringLength());
    if (name != "id") {
      json::fail("mesh." + std::string(name),
                 "mesh.id names an uploaded mesh, whose scheme and tags were fixed when it was "
                 "uploaded; mesh." +
                     std::string(name) + " cannot go with it (upload the changed mesh instead)");
    }
  }
  std::string id(json::string(*json::find(mesh, "id"), "mesh.id"));
  std::shared_ptr<const render::mesh::ControlMesh> found = meshes ? meshes->find(id) : nullptr;
  if (!found) {
    throw ApiError{404, "unknown_mesh",
                   "mesh.id " + json::quote(id) +
                       " is not a mesh this server holds (never uploaded, or evicted): upload it "
                       "again with POST /v1/meshes",
                   json::detailObject({{"field", "mesh.id"}, {"id", id}})};
  }
  return *found;
}

namespace {

// The bytes of a mesh file: mesh.data (text) or mesh.dataBase64 (any file, binary ones too).
std::string meshFileBytes(const Value& mesh, std::string_view format) {
  const Value* text = json::find(mesh, "data");
  const Value* encoded = json::find(mesh, "dataBase64");
  if (text && encoded) json::fail("mesh.dataBase64", "give mesh.data or mesh.dataBase64, not both");
  if (text) return std::string(json::string(*text, "mesh.data"));
  if (!encoded) {
    json::fail("mesh.data",
               "mesh.data (the file as text) or mesh.dataBase64 (the file in "
               "base64) is required with format " +
                   json::quote(format));
  }
  std::optional<std::vector<unsigned char>> bytes =
      decodeBase64(json::string(*encoded, "mesh.dataBase64"));
  if (!bytes) json::fail("mesh.dataBase64", "mesh.dataBase64 is not base64");
  return std::string(bytes->begin(), bytes->end());
}

// A file Assimp reads (formats/assimp_import.h), with what the import did as warnings: the
// scheme it chose, the meshes it merged, the corners it welded.
render::mesh::ControlMesh importMeshFile(const Value& mesh, formats::ImportFormat format,
                                         const JobLimits& limits,
                                         std::vector<std::string>& warnings) {
  warnUnknownFields(mesh, "mesh", {"format", "data", "dataBase64", "scheme", "name"}, warnings);
  formats::ImportOptions options;
  if (const Value* v = json::find(mesh, "scheme")) options.scheme = readScheme(*v, "mesh.scheme");
  if (const Value* v = json::find(mesh, "name")) options.meshName = json::string(*v, "mesh.name");
  const std::string bytes = meshFileBytes(mesh, formats::importFormatName(format));
  formats::ImportedMesh imported = formats::importMesh(bytes, format, options, limits.mesh);
  render::mesh::validateMesh(imported.mesh, limits.mesh);
  std::string read = std::string("mesh read from ") + formats::importFormatName(format) + ": " +
                     std::to_string(imported.mesh.faceCount()) + " faces, " +
                     std::to_string(imported.mesh.vertexCount()) + " vertices";
  if (imported.meshesMerged > 1)
    read += ", " + std::to_string(imported.meshesMerged) + " meshes merged";
  if (imported.verticesWelded > 0) {
    read += ", " + std::to_string(imported.verticesWelded) + " repeated corners welded";
  }
  if (imported.schemeChosen) {
    read +=
        std::string("; scheme ") + render::mesh::schemeName(imported.mesh.scheme) +
        (imported.mesh.scheme == render::mesh::Scheme::Loop ? " (every face is a triangle)"
                                                            : " (not every face is a triangle)");
  }
  warnings.push_back(std::move(read));
  for (std::string& w : imported.warnings) warnings.push_back("mesh " + std::move(w));
  return std::move(imported.mesh);
}

}  // namespace

render::mesh::ControlMesh parseMesh(const Value& mesh, const JobLimits& limits,
                                    std::vector<std::string>& warnings,
                                    render::mesh::MeshCache* meshes) {
  json::requireObject(mesh, "mesh");
  if (json::find(mesh, "id")) return storedMesh(mesh, meshes);
  std::string_view format = "json";
  if (const Value* v = json::find(mesh, "format")) format = json::string(*v, "mesh.format");
  if (format == "obj") {
    warnUnknownFields(mesh, "mesh", {"format", "data", "dataBase64", "scheme"}, warnings);
    const std::string text = meshFileBytes(mesh, "obj");
    render::mesh::Scheme scheme = render::mesh::Scheme::CatmullClark;
    if (const Value* v = json::find(mesh, "scheme")) scheme = readScheme(*v, "mesh.scheme");
    formats::ObjMesh obj = formats::readObj(text, scheme, limits.mesh);
    for (std::string& w : obj.warnings) warnings.push_back("mesh " + std::move(w));
    return std::move(obj.mesh);
  }
  if (format == "json") {
    if (json::find(mesh, "data") || json::find(mesh, "dataBase64")) {
      json::fail("mesh.data",
                 "mesh.data is read only with a file format (\"obj\", \"glb\", ...); the JSON "
                 "form puts points, faceVertexCounts, faceVertexIndices, ... directly in mesh");
    }
    warnUnknownFields(
        mesh, "mesh",
        {"format", "scheme", "points", "faceVertexCounts", "faceVertexIndices", "creaseIndices",
         "creaseLengths", "creaseSharpnesses", "cornerIndices", "cornerSharpnesses", "holeIndices",
         "interpolateBoundary", "creaseMethod", "triangleSubdivision"},
        warnings);
    return readJsonMesh(mesh, "mesh", limits.mesh);
  }
  if (std::optional<formats::ImportFormat> imported = formats::importFormatNamed(format)) {
    return importMeshFile(mesh, *imported, limits, warnings);
  }
  json::fail("mesh.format", "mesh.format must be one of " + request::meshFormatList() + "; got " +
                                json::quote(format));
}

// "turntable": {"frames", "elevationDeg", "fps"}, checked against the job it turns.
Turntable readTurntable(const Value& value, const render::pipeline::RenderJob& job,
                        const JobLimits& limits, std::vector<std::string>& warnings) {
  json::requireObject(value, "turntable");
  warnUnknownFields(value, "turntable", {"frames", "elevationDeg", "fps"}, warnings);
  Turntable out;
  if (job.camera.orbit) out.elevationDeg = job.camera.orbit->elevationDeg;
  if (const Value* v = json::find(value, "frames"))
    out.frames = json::integer(*v, "turntable.frames");
  if (out.frames < 2) json::fail("turntable.frames", "turntable.frames must be at least 2");
  if (static_cast<size_t>(out.frames) > limits.maxFrames) {
    throw tooLarge("maxFrames", "turntable.frames",
                   "turntable.frames " + std::to_string(out.frames) + " exceeds limit maxFrames (" +
                       std::to_string(limits.maxFrames) + ")");
  }
  if (const Value* v = json::find(value, "elevationDeg")) {
    out.elevationDeg = json::number(*v, "turntable.elevationDeg");
    if (!(std::abs(out.elevationDeg) <= 89)) {
      json::fail("turntable.elevationDeg", "turntable.elevationDeg must be in -89..89");
    }
  }
  if (const Value* v = json::find(value, "fps")) {
    out.fps = json::number(*v, "turntable.fps");
    if (!(out.fps >= 1 && out.fps <= 50))
      json::fail("turntable.fps", "turntable.fps must be in 1..50");
  }
  if (job.camera.eye) {
    json::fail("camera.eye",
               "a turntable orbits the target: place its first view with "
               "camera.orbit (azimuthDeg, distance), or leave the eye out");
  }
  if (!job.frames.empty()) json::fail("turntable", "turntable and frames cannot go together");
  if (job.method == Method::Limit) {
    json::fail("turntable",
               "method \"limit\" is the reference; turn a method with "
               "\"reference\": true to see both");
  }
  return out;
}

RenderRequest parseDocument(const Value& root, const JobLimits& limits,
                            render::mesh::MeshCache* meshes) {
  if (!root.IsObject()) {
    json::fail("", "the request body must be a JSON object, got " + json::describe(root));
  }
  RenderRequest request;
  std::vector<std::string>& warnings = request.warnings;
  render::pipeline::RenderJob& job = request.job;
  warnUnknownFields(
      root, "",
      {"mesh", "camera", "method", "params", "shading", "outputs", "antialias", "background",
       "reference", "imageFormat", "imageQuality", "frames", "displacement", "turntable"},
      warnings);
  if (const Value* v = json::find(root, "camera")) {
    job.camera = request::parseCamera(*v, limits, warnings);
  }
  if (const Value* v = json::find(root, "method")) job.method = parseMethod(*v);
  if (const Value* v = json::find(root, "params")) job.params = parseParams(*v, limits, warnings);
  if (const Value* v = json::find(root, "shading")) job.shading = request::parseShading(*v);
  bool animation = false;
  if (const Value* v = json::find(root, "outputs")) job.outputs = readOutputs(*v, &animation);
  if (const Value* v = json::find(root, "antialias")) {
    job.outputs.antialias = request::parseAntialias(*v);
  }
  if (job.outputs.contours && job.method != Method::Silhouette) {
    json::fail("outputs", "output \"contours\" is drawn by method \"silhouette\" only");
  }
  if (job.outputs.patches && job.method != Method::Patches) {
    json::fail("outputs", "output \"patches\" is drawn by method \"patches\" only");
  }
  if (job.outputs.cage && job.method == Method::Limit) {
    json::fail("outputs",
               "output \"cage\" is drawn over a method's own image; method \"limit\" "
               "has none");
  }
  if (job.method != Method::Uniform &&
      (job.params.engine != render::pipeline::Engine::Auto || job.params.pushToLimit)) {
    warnings.push_back(
        "params.engine and params.pushToLimit are read by method \"uniform\" "
        "only; ignored");
  }
  if (const Value* v = json::find(root, "reference"))
    job.reference = json::boolean(*v, "reference");
  if (job.outputs.diff && (!job.reference || job.method == Method::Limit)) {
    json::fail("outputs",
               "output \"diff\" compares the method's colour with the reference: it needs "
               "\"reference\": true and a method other than \"limit\"");
  }
  request.encoding = request::parseImageEncoding(root);
  if (const Value* v = json::find(root, "background")) {
    job.outputs.background = request::parseBackground(*v);
  }

  const Value* mesh = json::find(root, "mesh");
  if (!mesh) json::fail("mesh", "mesh is required");
  job.mesh = parseMesh(*mesh, limits, warnings, meshes);
  if (const Value* v = json::find(root, "frames")) job.frames = readFrames(*v, job, limits);
  if (const Value* v = json::find(root, "displacement")) {
    job.displacement = request::parseDisplacement(*v, warnings);
  }

  if (const Value* v = json::find(root, "turntable")) {
    request.turntable = readTurntable(*v, job, limits, warnings);
  }
  if (animation && !request.turntable) {
    json::fail("outputs", "output \"turntable\" is the animation of a \"turntable\": give one");
  }
  if (request.turntable) request.turntable->animation = animation;
  request::checkCameraAgainstMesh(job.camera, job.mesh);
  return request;
}

}  // namespace

namespace request {

void parseJson(std::string_view body, rapidjson::Document& document) {
  // Iterative parsing: a deeply nested body must not exhaust the stack. UTF-8 is validated so
  // that text echoed back in messages is valid JSON. No kParseFullPrecisionFlag: RapidJSON
  // 1.1.0's full-precision conversion (StrtodDiyFp) reads out of bounds on numbers such as
  // 0.00000000017994409662966923262e-320 and crashed the server (found by fuzz/json_mesh); the
  // default conversion is within a few units in the last place, far below what a mesh or a
  // camera can show.
  constexpr unsigned kFlags =
      rapidjson::kParseIterativeFlag | rapidjson::kParseValidateEncodingFlag;
  document.Parse<kFlags>(body.data(), body.size());
  if (document.HasParseError()) {
    size_t offset = document.GetErrorOffset();
    throw ApiError{400, "invalid_json",
                   std::string("the request body is not valid JSON: ") +
                       rapidjson::GetParseError_En(document.GetParseError()) + " (at offset " +
                       std::to_string(offset) + ")",
                   "{\"offset\": " + std::to_string(offset) + "}"};
  }
}

void warnUnknownFields(const Value& object, const std::string& prefix,
                       std::initializer_list<const char*> known,
                       std::vector<std::string>& warnings) {
  api::warnUnknownFields(object, prefix, known, warnings);
}

std::string meshFormatList() {
  std::string list = "\"obj\", \"json\"";
  for (const std::string& name : formats::importFormatNames()) list += ", \"" + name + "\"";
  return list;
}

bool readsThroughAssimp(const Value& mesh) {
  const Value* format = mesh.IsObject() ? json::find(mesh, "format") : nullptr;
  return format && format->IsString() &&
         formats::importFormatNamed({format->GetString(), format->GetStringLength()}).has_value();
}

render::mesh::ControlMesh parseMesh(const Value& mesh, const JobLimits& limits,
                                    std::vector<std::string>& warnings,
                                    render::mesh::MeshCache* meshes) {
  return api::parseMesh(mesh, limits, warnings, meshes);
}

void parseSilhouetteParams(const Value& params, const JobLimits& limits,
                           render::pipeline::MethodParams& out) {
  api::parseSilhouetteParams(params, limits, out);
}

render::pipeline::Outputs parseOutputs(const Value& outputs) { return readOutputs(outputs); }

render::subdiv::DisplacementSpec parseDisplacement(const Value& displacement,
                                                   std::vector<std::string>& warnings) {
  using render::subdiv::DisplacementFunction;
  json::requireObject(displacement, "displacement");
  warnUnknownFields(displacement, "displacement", {"function", "amplitude", "frequency"}, warnings);
  render::subdiv::DisplacementSpec out;
  const Value* function = json::find(displacement, "function");
  if (!function) json::fail("displacement.function", "displacement.function is required");
  out.function = json::choice<DisplacementFunction>(
      *function, "displacement.function",
      {{"bumps", DisplacementFunction::Bumps}, {"ripples", DisplacementFunction::Ripples}});
  const Value* amplitude = json::find(displacement, "amplitude");
  const Value* frequency = json::find(displacement, "frequency");
  out.amplitude = amplitude ? json::number(*amplitude, "displacement.amplitude") : 0.02;
  out.frequency = frequency ? json::number(*frequency, "displacement.frequency") : 4;
  return out;
}

render::Shading parseShading(const Value& shading) {
  return json::choice<render::Shading>(shading, "shading",
                                       {{"flat", render::Shading::Flat},
                                        {"smooth", render::Shading::Smooth},
                                        {"normal-map", render::Shading::NormalMap}});
}

int parseAntialias(const Value& antialias) {
  const int samples = json::integer(antialias, "antialias");
  if (samples != 1 && samples != 4 && samples != 8 && samples != 16) {
    json::fail("antialias",
               "antialias must be 1, 4, 8 or 16 samples per pixel, got " + std::to_string(samples));
  }
  return samples;
}

render::image::Encoding parseImageEncoding(const Value& request) {
  render::image::Encoding encoding;
  if (const Value* v = json::find(request, "imageFormat")) {
    encoding.format = json::choice<render::image::Format>(*v, "imageFormat",
                                                          {{"png", render::image::Format::Png},
                                                           {"exr", render::image::Format::Exr},
                                                           {"jpeg", render::image::Format::Jpeg},
                                                           {"webp", render::image::Format::Webp}});
  }
  if (const Value* v = json::find(request, "imageQuality")) {
    encoding.quality = json::integer(*v, "imageQuality");
    if (encoding.quality < 1 || encoding.quality > 100) {
      json::fail("imageQuality",
                 "imageQuality must be in 1..100, got " + std::to_string(encoding.quality));
    }
  }
  return encoding;
}

render::Background parseBackground(const Value& value) {
  const std::string text(json::string(value, "background"));
  render::Background background;
  if (text == "transparent") return background;
  background.transparent = false;
  if (text == "white") return background;
  const bool hex = text.size() == 7 && text[0] == '#' &&
                   text.find_first_not_of("0123456789abcdefABCDEF", 1) == std::string::npos;
  if (!hex) {
    json::fail("background",
               "background must be \"transparent\", \"white\" or an sRGB colour "
               "\"#rrggbb\", got \"" +
                   text.substr(0, 40) + "\"");
  }
  for (int c = 0; c < 3; ++c) {
    background.rgb[c] = std::stoi(text.substr(1 + 2 * c, 2), nullptr, 16) / 255.0f;
  }
  return background;
}

Method parseMethod(const Value& value) { return api::parseMethod(value); }

render::pipeline::MethodParams parseParams(const Value& params, const JobLimits& limits,
                                           std::vector<std::string>& warnings) {
  return api::parseParams(params, limits, warnings);
}

}  // namespace request

RenderRequest parseRenderRequest(std::string_view body, const JobLimits& limits,
                                 render::mesh::MeshCache* meshes) {
  rapidjson::Document document;
  request::parseJson(body, document);
  try {
    return parseDocument(document, limits, meshes);
  } catch (const render::InputError& error) {
    throw fromInputError(error);
  }
}

}  // namespace limn::api
