// writeCompareResponse: CompareResult -> the 200 answer of POST /v1/compare, one table:
//   {"rows": [{"label", "method", "params", "shading", "camera", "metrics", "stats", "timings",
//              "images"?, "warnings", "error"?}],
//    "cameras": [resolved camera, ...],
//    "reference": {"timings": {"referenceMs"}, "cameras": [{"camera", "timings", "stats",
//                  "images"?, "warnings"}]},
//    "stats", "timings", "warnings"}
// Rows, metrics, stats and images are written by the same code as /v1/render's answer.
#include <chrono>

#include "api/compare_api.h"
#include "api/json_util.h"
#include "api/response_parts.h"

namespace limn::api {

namespace {

using json::writeNumber;
using json::Writer;
using render::pipeline::CompareResult;
using render::pipeline::CompareRow;

void numberField(Writer& w, const char* key, double value) {
  w.Key(key);
  writeNumber(w, value);
}

bool anyImages(const render::pipeline::Outputs& o) {
  return o.color || o.mask || o.depth || o.normal || o.wireframe || o.contours || o.cage || o.diff;
}

// A row that could not be made: its error as /v1/render would have answered it.
void writeRowError(Writer& w, const render::pipeline::RowError& error) {
  ApiError api = fromInputError(render::InputError(error.kind, error.subject, error.message));
  w.Key("error");
  w.StartObject();
  w.Key("status");
  w.Int(api.status);
  w.Key("code");
  json::writeString(w, api.code);
  w.Key("message");
  json::writeString(w, api.message);
  w.Key("detail");
  w.RawValue(api.detailJson.data(), api.detailJson.size(), rapidjson::kObjectType);
  w.EndObject();
}

void writeRowTimings(Writer& w, const render::pipeline::Timings& t) {
  w.Key("timings");
  w.StartObject();
  numberField(w, "approxMs", t.approxMs);
  numberField(w, "rasterMs", t.rasterMs);
  numberField(w, "metricsMs", t.metricsMs);
  numberField(w, "totalMs", t.totalMs);
  w.EndObject();
}

void writeRow(Writer& w, const CompareRow& row, const CompareRequest& request,
              std::vector<std::string>& warnings, const response::EncodedImages& encoded) {
  const render::pipeline::CompareMethod& method = request.job.methods[row.method];
  w.StartObject();
  w.Key("label");
  json::writeString(w, request.labels[row.method]);
  w.Key("method");
  w.String(render::pipeline::methodName(method.method));
  w.Key("params");
  const std::string& params = request.paramsJson[row.method];
  w.RawValue(params.data(), params.size(), rapidjson::kObjectType);
  w.Key("shading");
  w.String(method.shading == render::Shading::Flat        ? "flat"
           : method.shading == render::Shading::NormalMap ? "normal-map"
                                                          : "smooth");
  w.Key("camera");
  w.Uint64(row.camera);
  if (row.error) {
    writeRowError(w, *row.error);
  } else {
    w.Key("metrics");
    response::writeMetrics(w, row.metrics);
    w.Key("stats");
    response::writeStats(w, row.stats);
    writeRowTimings(w, row.timings);
    if (anyImages(request.job.outputs)) {
      w.Key("images");
      response::writeImages(w, row.images, request.job.outputs, request.encoding, "method",
                            warnings, &encoded);
    }
  }
  w.Key("warnings");
  json::writeStrings(w, row.warnings);
  w.EndObject();
}

void writeReference(Writer& w, const CompareResult& result, const CompareRequest& request,
                    std::vector<std::string>& warnings, const response::EncodedImages& encoded) {
  double referenceMs = 0;
  for (const auto& ref : result.references) referenceMs += ref.referenceMs;
  w.Key("reference");
  w.StartObject();
  w.Key("timings");
  w.StartObject();
  numberField(w, "referenceMs", referenceMs);
  w.EndObject();
  w.Key("cameras");
  w.StartArray();
  for (size_t c = 0; c < result.references.size(); ++c) {
    const render::pipeline::CompareReference& ref = result.references[c];
    w.StartObject();
    w.Key("camera");
    w.Uint64(c);
    numberField(w, "accuracyPx", ref.stats.accuracyPx);
    w.Key("timings");
    w.StartObject();
    numberField(w, "referenceMs", ref.referenceMs);
    response::writeReferenceStages(w, ref.stats, 0);
    w.EndObject();
    w.Key("stats");
    w.StartObject();
    w.Key("referenceTriangles");
    w.Uint64(ref.stats.triangles);
    w.Key("hits");
    w.Uint64(ref.stats.hits);
    w.EndObject();
    if (anyImages(request.job.outputs)) {
      w.Key("images");
      response::writeImages(w, ref.images, request.job.outputs, request.encoding, "reference",
                            warnings, &encoded);
    }
    w.Key("warnings");
    json::writeStrings(w, ref.warnings);
    w.EndObject();
  }
  w.EndArray();
  w.EndObject();
}

// Every image of the answer, encoded at once (response::EncodedImages).
response::EncodedImages encodeImages(const CompareResult& result, const CompareRequest& request) {
  std::vector<response::EncodedImages::Owned> sets;
  if (anyImages(request.job.outputs)) {
    for (const CompareRow& row : result.rows) {
      if (!row.error) sets.push_back({&row.images, "method"});
    }
    for (const auto& ref : result.references) sets.push_back({&ref.images, "reference"});
  }
  return response::EncodedImages(sets, request.job.outputs, request.encoding);
}

}  // namespace

std::string writeCompareResponse(const CompareResult& result, const CompareRequest& request,
                                 double parseMs) {
  using Clock = std::chrono::steady_clock;
  const Clock::time_point start = Clock::now();
  std::vector<std::string> warnings = request.warnings;
  const response::EncodedImages encoded = encodeImages(result, request);
  rapidjson::StringBuffer buffer;
  Writer w(buffer);
  w.StartObject();
  w.Key("rows");
  w.StartArray();
  double rowsMs = 0;
  size_t failed = 0;
  for (const CompareRow& row : result.rows) {
    writeRow(w, row, request, warnings, encoded);
    rowsMs += row.timings.totalMs;
    failed += row.error.has_value();
  }
  w.EndArray();
  w.Key("cameras");
  w.StartArray();
  for (const auto& ref : result.references) response::writeCamera(w, ref.camera);
  w.EndArray();
  writeReference(w, result, request, warnings, encoded);

  w.Key("stats");
  w.StartObject();
  w.Key("controlVertices");
  w.Int(result.controlVertices);
  w.Key("controlFaces");
  w.Int(result.controlFaces);
  w.Key("rows");
  w.Uint64(result.rows.size());
  w.Key("failedRows");
  w.Uint64(failed);
  w.EndObject();

  double referenceMs = 0;
  for (const auto& ref : result.references) referenceMs += ref.referenceMs;
  const double encodeMs = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
  w.Key("timings");
  w.StartObject();
  numberField(w, "parseMs", parseMs);
  numberField(w, "surfaceMs", result.surfaceMs);
  numberField(w, "rowsMs", rowsMs);
  numberField(w, "referenceMs", referenceMs);
  numberField(w, "encodeMs", encodeMs);
  numberField(w, "totalMs", parseMs + result.totalMs + encodeMs);
  w.EndObject();
  w.Key("warnings");
  json::writeStrings(w, warnings);
  w.EndObject();
  return {buffer.GetString(), buffer.GetSize()};
}

}  // namespace limn::api
