// writeSilhouetteJson: ContourResult -> the JSON answer of POST /v1/silhouette. Numbers that
// are not finite are written as null.
#include <chrono>

#include "api/json_util.h"
#include "api/response_parts.h"
#include "api/silhouette_api.h"

namespace limn::api {

namespace {

using json::writeNumber;
using json::Writer;

void numberField(Writer& w, const char* key, double value) {
  w.Key(key);
  writeNumber(w, value);
}

void countField(Writer& w, const char* key, size_t value) {
  w.Key(key);
  w.Uint64(value);
}

void writeNumbers(Writer& w, std::initializer_list<double> values) {
  w.StartArray();
  for (double v : values) writeNumber(w, v);
  w.EndArray();
}

void writePoint(Writer& w, const render::silhouette::PolylinePoint& p, bool visible) {
  w.StartObject();
  w.Key("position");
  writeNumbers(w, {p.position.x, p.position.y, p.position.z});
  w.Key("pixel");
  writeNumbers(w, {p.pixel.x, p.pixel.y});
  numberField(w, "depth", p.pixel.z);
  w.Key("normal");
  writeNumbers(w, {p.normal.x, p.normal.y, p.normal.z});
  w.Key("face");
  w.Int(p.face);
  w.Key("uv");
  writeNumbers(w, {p.uv.x, p.uv.y});
  w.Key("edgePoint");
  w.Bool(p.edgePoint);
  w.Key("visible");
  w.Bool(visible);
  w.EndObject();
}

void writePolyline(Writer& w, const render::pipeline::ContourLine& line) {
  w.StartObject();
  w.Key("closed");
  w.Bool(line.closed);
  w.Key("points");
  w.StartArray();
  for (size_t i = 0; i < line.points.size(); ++i) writePoint(w, line.points[i], line.visible[i]);
  w.EndArray();
  w.Key("pieces");
  w.StartArray();
  for (const render::silhouette::PolylinePiece& piece : line.pieces) {
    w.StartObject();
    w.Key("start");
    w.Int(piece.start);
    w.Key("end");
    w.Int(piece.end);
    w.Key("visible");
    w.Bool(piece.visible);
    w.EndObject();
  }
  w.EndArray();
  w.EndObject();
}

void writeStats(Writer& w, const render::pipeline::ContourStats& s) {
  w.StartObject();
  w.Key("controlVertices");
  w.Int(s.controlVertices);
  w.Key("controlFaces");
  w.Int(s.controlFaces);
  countField(w, "polylines", s.polylines);
  countField(w, "closedPolylines", s.closedPolylines);
  countField(w, "points", s.points);
  countField(w, "hiddenPoints", s.hiddenPoints);
  countField(w, "visiblePieces", s.visiblePieces);
  countField(w, "hiddenPieces", s.hiddenPieces);
  countField(w, "referenceTriangles", s.referenceTriangles);
  countField(w, "raysCast", s.raysCast);
  response::writeSilhouetteStats(w, s.silhouette, s.presubdivided);
  w.EndObject();
}

}  // namespace

std::string writeSilhouetteJson(const render::pipeline::ContourResult& result,
                                const SilhouetteRequest& request) {
  using Clock = std::chrono::steady_clock;
  const Clock::time_point start = Clock::now();
  rapidjson::StringBuffer buffer;
  Writer w(buffer);
  w.StartObject();
  w.Key("camera");
  response::writeCamera(w, result.camera);
  w.Key("polylines");
  w.StartArray();
  for (const render::pipeline::ContourLine& line : result.polylines) writePolyline(w, line);
  w.EndArray();
  w.Key("stats");
  writeStats(w, result.stats);
  const double encodeMs = std::chrono::duration<double, std::milli>(Clock::now() - start).count();

  const render::pipeline::ContourTimings& t = result.timings;
  w.Key("timings");
  w.StartObject();
  numberField(w, "parseMs", t.parseMs);
  numberField(w, "surfaceMs", t.surfaceMs);
  numberField(w, "contourMs", t.contourMs);
  numberField(w, "chainMs", t.chainMs);
  numberField(w, "visibilityMs", t.visibilityMs);
  numberField(w, "referenceTessellateMs", t.referenceTessellateMs);
  numberField(w, "bvhMs", t.bvhMs);
  numberField(w, "raysMs", t.raysMs);
  numberField(w, "encodeMs", encodeMs);
  numberField(w, "totalMs", t.parseMs + t.totalMs + encodeMs);
  w.EndObject();

  w.Key("warnings");
  w.StartArray();
  for (const std::string& warning : request.warnings) json::writeString(w, warning);
  for (const std::string& warning : result.warnings) json::writeString(w, warning);
  w.EndArray();
  w.EndObject();
  return {buffer.GetString(), buffer.GetSize()};
}

}  // namespace limn::api
