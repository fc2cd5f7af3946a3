#include "api/work_estimate.h"

#include <rapidjson/document.h>

#include <algorithm>
#include <cmath>

#include "render/core/camera.h"

namespace limn::api {
namespace {

using Value = rapidjson::Value;

const Value* member(const Value& object, const char* name) {
  if (!object.IsObject()) return nullptr;
  auto it = object.FindMember(name);
  return it == object.MemberEnd() ? nullptr : &it->value;
}

double numberOr(const Value* value, double fallback) {
  return value && value->IsNumber() ? value->GetDouble() : fallback;
}

// Pixels of one camera object (or of the default camera).
double cameraPixels(const Value* camera) {
  const double side = render::kDefaultImageSide;
  if (!camera || !camera->IsObject()) return side * side;
  return std::max(1.0, numberOr(member(*camera, "width"), side)) *
         std::max(1.0, numberOr(member(*camera, "height"), side));
}

// Faces of the request's mesh: OBJ "f" lines, JSON faceVertexCounts, or an uploaded mesh.
double meshFaces(const Value* mesh, const std::function<int(const std::string&)>& facesOfMesh) {
  if (!mesh || !mesh->IsObject()) return 0;
  if (const Value* id = member(*mesh, "id"); id && id->IsString()) {
    const int faces = facesOfMesh ? facesOfMesh(id->GetString()) : -1;
    return faces < 0 ? 0 : faces;
  }
  if (const Value* counts = member(*mesh, "faceVertexCounts"); counts && counts->IsArray()) {
    return counts->Size();
  }
  if (const Value* data = member(*mesh, "data"); data && data->IsString()) {
    std::string_view text(data->GetString(), data->GetStringLength());
    double faces = 0;
    for (size_t at = 0; (at = text.find("\nf ", at)) != std::string_view::npos; ++at) ++faces;
    if (text.substr(0, 2) == "f ") ++faces;
    return faces;
  }
  return 0;
}

bool isLoop(const Value* mesh) {
  const Value* scheme = mesh ? member(*mesh, "scheme") : nullptr;
  return scheme && scheme->IsString() && std::string_view(scheme->GetString()) == "loop";
}

// The triangles one method makes of `faces` control faces at `pixels` of image.
double methodTriangles(const Value* methodValue, const Value* params, double faces, double pixels,
                       bool loop) {
  std::string method = "adaptive";
  if (methodValue && methodValue->IsString()) method = methodValue->GetString();
  const double perFace = loop ? 1.0 : 2.0;  // triangles of one face at level 0
  if (method == "coarse") return faces * perFace;
  if (method == "uniform") {
    const double level =
        std::clamp(numberOr(params ? member(*params, "level") : nullptr, 3), 0.0, 8.0);
    return faces * perFace * std::pow(4.0, level);
  }
  // Adaptive dicing (adaptive, limit, silhouette, patches): bounded by the screen, about two
  // triangles per dicingRate^2 pixels of the surface's projected area (half the image here),
  // and at least the cage's.
  const double rate = std::max(0.25, numberOr(params ? member(*params, "dicingRate") : nullptr, 1));
  return faces * perFace + pixels / (rate * rate);
}

// Each method's entry of /v1/compare: "name" or {"method", "params"}.
void methodOf(const Value& entry, const Value*& method, const Value*& params) {
  if (entry.IsString()) {
    method = &entry;
    params = nullptr;
  } else {
    method = member(entry, "method");
    params = member(entry, "params");
  }
}

}  // namespace

WorkSize estimateWork(std::string_view path, std::string_view body,
                      const std::function<int(const std::string&)>& facesOfMesh) {
  WorkSize work;
  if (body.size() > kMaxReadBytes) {
    work.unread = true;
    return work;
  }
  rapidjson::Document root;
  root.Parse(body.data(), body.size());
  if (root.HasParseError() || !root.IsObject()) return work;  // refused at once by the worker
  const Value* mesh = member(root, "mesh");
  work.controlFaces = meshFaces(mesh, facesOfMesh);
  const bool loop = isLoop(mesh);
  work.samplesCost = numberOr(member(root, "antialias"), 4) > 1 ? 2.5 : 1.0;

  if (path == "/v1/compare") {
    double pixels = 0;
    if (const Value* cameras = member(root, "cameras"); cameras && cameras->IsArray()) {
      for (const Value& camera : cameras->GetArray()) pixels += cameraPixels(&camera);
    } else {
      pixels = cameraPixels(member(root, "camera"));
    }
    const double ss = numberOr(member(root, "metricSupersample"), 4);
    work.referencePixels = pixels * ss * ss;
    if (const Value* methods = member(root, "methods"); methods && methods->IsArray()) {
      for (const Value& entry : methods->GetArray()) {
        const Value *method = nullptr, *params = nullptr;
        methodOf(entry, method, params);
        work.pixels += pixels;
        work.triangles += methodTriangles(method, params, work.controlFaces, pixels, loop);
      }
    }
    return work;
  }
  const double pixels = cameraPixels(member(root, "camera"));
  if (path == "/v1/implicit") {
    const Value* polygonizer = member(root, "polygonizer");
    const double resolution =
        numberOr(polygonizer ? member(*polygonizer, "resolution") : nullptr, 80);
    work.implicitCells = std::pow(std::clamp(resolution, 1.0, 4096.0), 3);
    work.pixels = pixels;
    const Value* reference = member(root, "reference");
    if (reference && reference->IsBool() && reference->GetBool())
      work.referencePixels = pixels * 16;
    return work;
  }
  const Value* params = member(root, "params");
  double frames = 1;
  if (const Value* f = member(root, "frames"); f && f->IsArray())
    frames = std::max<double>(1, f->Size());
  work.pixels = pixels * frames;
  work.triangles = methodTriangles(member(root, "method"), params, work.controlFaces, pixels, loop);
  const Value* reference = member(root, "reference");
  if (reference && reference->IsBool() && reference->GetBool()) {
    const double ss = numberOr(params ? member(*params, "metricSupersample") : nullptr, 4);
    work.referencePixels = pixels * ss * ss * frames;
  }
  if (path == "/v1/silhouette") work.pixels = pixels * 0.2;  // curves, no raster of the surface
  return work;
}

double referenceSeconds(const WorkSize& work) {
  // Per unit on the 2-core llvmpipe machine: a request's fixed cost (parse, answer), raster and
  // PNG per output pixel, the reference's rays and metric masks per supersampled pixel,
  // refinement and raster per triangle, polygonisation per implicit cell.
  constexpr double kFixed = 2e-3, kPixel = 4e-8, kReferenceSample = 8e-8, kTriangle = 8e-7,
                   kCell = 4e-9;
  if (work.unread) return 10.0;
  return kFixed + kPixel * work.samplesCost * work.pixels +
         kReferenceSample * work.referencePixels + kTriangle * work.triangles +
         kCell * work.implicitCells;
}

}  // namespace limn::api
