// handleTessellate: POST /v1/tessellate. The body is a /v1/render request; the answer is the
// approximation's mesh itself (render::pipeline::approximate: the triangles the method would
// rasterise, with their limit normals) as GLB, PLY or OBJ, chosen by the Accept header, for a
// client that draws it locally (a WebGL view while orbiting). Errors are JSON, as everywhere.
#include <chrono>

#include "api/accept.h"
#include "api/json_util.h"
#include "api/render_api.h"
#include "api/response_parts.h"
#include "formats/mesh_writers.h"
#include "render/pipeline/approximation.h"

namespace limn::api {

namespace {

// asset.extras of the GLB: what /v1/render's answer says about the same approximation.
std::string extrasJson(const render::pipeline::Approximation& a, const RenderRequest& request,
                       const std::vector<std::string>& warnings, double totalMs) {
  rapidjson::StringBuffer buffer;
  json::Writer w(buffer);
  w.StartObject();
  w.Key("method");
  w.String(render::pipeline::methodName(request.job.method));
  w.Key("stats");
  w.StartObject();
  w.Key("controlVertices");
  w.Int(a.stats.controlVertices);
  w.Key("controlFaces");
  w.Int(a.stats.controlFaces);
  w.Key("triangles");
  w.Uint64(a.stats.triangles);
  w.Key("vertices");
  w.Uint64(a.stats.vertices);
  w.EndObject();
  w.Key("timings");
  w.StartObject();
  w.Key("surfaceMs");
  json::writeNumber(w, a.timings.surfaceMs);
  w.Key("approxMs");
  json::writeNumber(w, a.timings.approxMs);
  w.Key("totalMs");
  json::writeNumber(w, totalMs);
  w.EndObject();
  w.Key("camera");
  response::writeCamera(w, a.camera);
  w.Key("warnings");
  json::writeStrings(w, warnings);
  w.EndObject();
  return {buffer.GetString(), buffer.GetSize()};
}

}  // namespace

Answer handleTessellate(std::string_view body, std::string_view accept,
                        const render::pipeline::JobLimits& limits,
                        const render::CancelToken& cancel, render::mesh::MeshCache* meshes) {
  return answerOrError("tessellation", [&] {
    using Clock = std::chrono::steady_clock;
    const Clock::time_point start = Clock::now();
    const std::optional<MeshFormat> format = chooseMeshFormat(accept);
    if (!format) {
      throw ApiError{406, "not_acceptable",
                     "POST /v1/tessellate answers model/gltf-binary, application/x-ply or "
                     "text/plain (OBJ); the Accept header allows none of them",
                     "{\"accept\":[\"model/gltf-binary\",\"application/x-ply\",\"text/plain\"]}"};
    }
    RenderRequest request = parseRenderRequest(body, limits, meshes);
    render::pipeline::Approximation approx =
        render::pipeline::approximate(request.job, limits, cancel);

    std::vector<std::string> warnings = request.warnings;
    if (request.job.reference) warnings.push_back("reference is not computed by /v1/tessellate");
    warnings.insert(warnings.end(), approx.warnings.begin(), approx.warnings.end());
    const double totalMs = std::chrono::duration<double, std::milli>(Clock::now() - start).count();

    Answer answer;
    answer.contentType = meshMime(*format);
    std::vector<std::string> comments = {
        std::string("limn ") + render::pipeline::methodName(request.job.method) + ": " +
        std::to_string(approx.stats.triangles) + " triangles, " +
        std::to_string(approx.stats.vertices) + " vertices, normals per vertex"};
    for (const std::string& w : warnings) comments.push_back("warning: " + w);
    switch (*format) {
      case MeshFormat::Glb:
        answer.body =
            formats::writeGlb(approx.mesh, extrasJson(approx, request, warnings, totalMs));
        break;
      case MeshFormat::Ply:
        answer.body = formats::writePly(approx.mesh, comments);
        break;
      case MeshFormat::Obj:
        answer.body = formats::writeObjMesh(approx.mesh, comments);
        break;
    }
    answer.headers.emplace_back("X-Limn-Triangles", std::to_string(approx.stats.triangles));
    answer.headers.emplace_back("X-Limn-Vertices", std::to_string(approx.stats.vertices));
    return answer;
  });
}

}  // namespace limn::api
