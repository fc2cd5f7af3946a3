// The parts of a request body that several endpoints share (POST /v1/render, /v1/silhouette
// and /v1/compare): the JSON document itself, the mesh, the camera, the method and its params
// and the notes about unknown fields. Defined in render_request.cpp, where /v1/render's reader
// uses them, and request_camera.cpp; every reader throws ApiError (400 invalid_json or
// invalid_request naming the field, 413 too_large) or render::InputError for the mesh.
#pragma once

#include <rapidjson/document.h>

#include <initializer_list>
#include <string>
#include <string_view>
#include <vector>

#include "render/core/camera.h"
#include "render/image/encode.h"
#include "render/mesh/control_mesh.h"
#include "render/mesh/mesh_cache.h"
#include "render/pipeline/compare.h"
#include "render/pipeline/render_job.h"
#include "render/subdiv/displacement.h"

namespace limn::api::request {

// Parses `body` into `document` (iterative, UTF-8 validated, full precision); a body that is
// not JSON is a 400 invalid_json with the byte offset.
void parseJson(std::string_view body, rapidjson::Document& document);

// A warning for each member of `object` not in `known` ("ignored unknown field "camera.x"").
void warnUnknownFields(const rapidjson::Value& object, const std::string& prefix,
                       std::initializer_list<const char*> known,
                       std::vector<std::string>& warnings);

render::CameraSpec parseCamera(const rapidjson::Value& camera,
                               const render::pipeline::JobLimits& limits,
                               std::vector<std::string>& warnings);

// The mesh in any form, checked against limits.mesh: "json" (the mesh itself), "obj" (limn's
// reader, OpenSubdiv's tag lines), or a file Assimp reads ("glb", "gltf", "ply", "stl", "fbx",
// "dae", "3ds", "off"; the file in mesh.data or mesh.dataBase64, mesh.name picks one of its
// meshes, the scheme chosen from the faces unless mesh.scheme names it); or {"id": ...}: one
// uploaded before and held by `meshes` (404 unknown_mesh when it is not there, or there is no
// cache).
render::mesh::ControlMesh parseMesh(const rapidjson::Value& mesh,
                                    const render::pipeline::JobLimits& limits,
                                    std::vector<std::string>& warnings,
                                    render::mesh::MeshCache* meshes = nullptr);

// "\"obj\", \"json\", \"gltf\", ...": every mesh.format, for messages.
std::string meshFormatList();

// Whether `mesh` is a file only Assimp reads: such a mesh is read in a worker process, never in
// the server's own (a job's spec takes it as an uploaded mesh's id instead).
bool readsThroughAssimp(const rapidjson::Value& mesh);

// params.presubdivide, searchSteps, curveSamples and contour, where present, into `out`.
void parseSilhouetteParams(const rapidjson::Value& params,
                           const render::pipeline::JobLimits& limits,
                           render::pipeline::MethodParams& out);

// "method" and "params" of /v1/render, with its field names in messages (POST /v1/compare
// re-labels them: api/compare_request.cpp).
render::pipeline::Method parseMethod(const rapidjson::Value& value);
render::pipeline::MethodParams parseParams(const rapidjson::Value& params,
                                           const render::pipeline::JobLimits& limits,
                                           std::vector<std::string>& warnings);

// One entry of /v1/compare's "methods" ({"method", "params", "shading", "label"} or just a
// name), with `field` ("methods[2]") in every message; its label made when it has none, and its
// params as given (JSON text) for the answer to echo. Defined in compare_request.cpp.
struct ParsedMethod {
  render::pipeline::CompareMethod method;
  std::string label, paramsJson;
};
ParsedMethod parseCompareMethod(const rapidjson::Value& entry, const std::string& field,
                                const render::pipeline::JobLimits& limits,
                                std::vector<std::string>& warnings);

// A 400 naming the camera field when the view cannot be drawn for this mesh: the eye on the
// target (given, or the mesh's centre), an eye or target more than 1e6 bounding radii from the
// mesh, an orthoHeight beyond 1e6 times the radius either way.
void checkCameraAgainstMesh(const render::CameraSpec& camera,
                            const render::mesh::ControlMesh& mesh);
// The same against any surface's bounding box (an implicit field's domain).
void checkCameraAgainstBounds(const render::CameraSpec& camera, const render::Bounds& bounds);

// "displacement": {"function": "bumps" | "ripples", "amplitude", "frequency"} (ranges are the
// engine's to check: pipeline::checkDisplacement).
render::subdiv::DisplacementSpec parseDisplacement(const rapidjson::Value& displacement,
                                                   std::vector<std::string>& warnings);

// "outputs": ["color", "mask", ...] (400 naming the element that is not an output's name).
render::pipeline::Outputs parseOutputs(const rapidjson::Value& outputs);

// "shading": "flat" | "smooth" | "normal-map".
render::Shading parseShading(const rapidjson::Value& shading);

// "imageFormat": "png" | "exr" | "jpeg" | "webp", and "imageQuality" (1..100, JPEG and WebP) of
// a request object; what it lacks keeps its default.
render::image::Encoding parseImageEncoding(const rapidjson::Value& request);

// "background": "transparent" | "white" | "#rrggbb" (an sRGB colour).
render::Background parseBackground(const rapidjson::Value& background);

// "antialias": samples per pixel of the colour outputs, 1, 4, 8 or 16 (400 naming it otherwise).
int parseAntialias(const rapidjson::Value& antialias);

}  // namespace limn::api::request
