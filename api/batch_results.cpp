// resultLines and readResultLine: batch rows as JSON lines, and back (api/batch_results.h).
#include "api/batch_results.h"

#include <rapidjson/document.h>

#include "api/json_util.h"

namespace limn::api {

namespace {

using json::Value;
using json::Writer;

void writeValue(Writer& w, const char* key, const Value& value) {
  w.Key(key);
  value.Accept(w);
}

void writeText(Writer& w, const char* key, const std::string& text) {
  w.Key(key);
  json::writeString(w, text);
}

void writeRaw(Writer& w, const char* key, const std::string& json) {
  w.Key(key);
  w.RawValue(json.data(), json.size(), rapidjson::kObjectType);
}

// What every line of a row carries, whatever its outcome: where it is in the plan.
void writePlace(Writer& w, const BatchPlan& plan, const BatchRow& row) {
  const BatchMesh& mesh = plan.meshes()[row.mesh];
  const MethodVariant& method = plan.spec().methods[row.method];
  const ViewSpec& view = plan.spec().views[row.view];
  writeText(w, "key", row.key);
  writeText(w, "mesh", mesh.name);
  writeText(w, "meshPath", mesh.path);
  writeText(w, "meshHash", mesh.hash);
  writeText(w, "label", method.label);
  writeText(w, "method", method.method);
  writeRaw(w, "params", method.paramsJson);
  writeText(w, "shading", method.shading);
  writeText(w, "view", view.label);
  w.Key("size");
  w.Int(plan.spec().size);
  w.Key("supersample");
  w.Int(plan.spec().supersample);
}

void writeError(Writer& w, int status, const std::string& code, const std::string& message) {
  w.Key("error");
  w.StartObject();
  w.Key("status");
  w.Int(status);
  writeText(w, "code", code);
  writeText(w, "message", message);
  w.EndObject();
}

std::string finished(rapidjson::StringBuffer& buffer) {
  return {buffer.GetString(), buffer.GetSize()};
}

// The group's rows when the comparison itself failed: each carries the answer's error.
std::vector<std::string> failedLines(const BatchPlan& plan, const RowGroup& group,
                                     const Answer& answer) {
  std::string code = "unknown", message = answer.body.substr(0, 500);
  rapidjson::Document body;
  body.Parse(answer.body.c_str(), answer.body.size());
  if (!body.HasParseError() && body.IsObject() && body.HasMember("error") &&
      body["error"].IsObject()) {
    const Value& e = body["error"];
    if (e.HasMember("code") && e["code"].IsString()) code = e["code"].GetString();
    if (e.HasMember("message") && e["message"].IsString()) message = e["message"].GetString();
  }
  std::vector<std::string> lines;
  for (size_t r : group.rows) {
    rapidjson::StringBuffer buffer;
    Writer w(buffer);
    w.StartObject();
    writePlace(w, plan, plan.rows()[r]);
    writeError(w, answer.status, code, message);
    w.EndObject();
    lines.push_back(finished(buffer));
  }
  return lines;
}

double numberOr(const Value& object, const char* key, double otherwise) {
  auto it = object.FindMember(key);
  return it != object.MemberEnd() && it->value.IsNumber() ? it->value.GetDouble() : otherwise;
}

std::string stringOr(const Value& object, const char* key) {
  auto it = object.FindMember(key);
  return it != object.MemberEnd() && it->value.IsString() ? it->value.GetString() : "";
}

}  // namespace

std::vector<std::string> resultLines(const BatchPlan& plan, const RowGroup& group,
                                     const Answer& answer) {
  if (answer.status != 200) return failedLines(plan, group, answer);
  rapidjson::Document body;
  body.Parse(answer.body.c_str(), answer.body.size());
  if (body.HasParseError() || !body.IsObject() || !body.HasMember("rows") ||
      !body["rows"].IsArray() || body["rows"].Size() != group.rows.size()) {
    return failedLines(
        plan, group,
        {502,
         "application/json",
         R"({"error":{"code":"bad_answer","message":"the comparison's answer does not have one row per method"}})",
         {},
         {},
         0});
  }
  const Value& reference = body["reference"]["cameras"][0];
  const Value& camera = body["cameras"][0];
  std::vector<std::string> lines;
  for (rapidjson::SizeType i = 0; i < group.rows.size(); ++i) {
    const Value& row = body["rows"][i];
    rapidjson::StringBuffer buffer;
    Writer w(buffer);
    w.StartObject();
    writePlace(w, plan, plan.rows()[group.rows[i]]);
    writeValue(w, "camera", camera);
    if (row.HasMember("error")) {
      const Value& e = row["error"];
      writeError(w, static_cast<int>(numberOr(e, "status", 500)), stringOr(e, "code"),
                 stringOr(e, "message"));
    } else {
      writeValue(w, "stats", row["stats"]);
      writeValue(w, "metrics", row["metrics"]);
      writeValue(w, "timings", row["timings"]);
    }
    // The reference was built once for all the group's rows; its time is the view's.
    w.Key("reference");
    w.StartObject();
    w.Key("referenceMs");
    json::writeNumber(w, numberOr(reference["timings"], "referenceMs", 0));
    w.Key("sharedBy");
    w.Uint64(group.rows.size());
    w.Key("sceneCached");
    w.Bool(reference["timings"]["referenceStages"]["sceneCached"].GetBool());
    w.EndObject();
    writeValue(w, "warnings", row["warnings"]);
    w.EndObject();
    lines.push_back(finished(buffer));
  }
  return lines;
}

std::optional<std::string> errorMessageOf(std::string_view body) {
  rapidjson::Document d;
  d.Parse(body.data(), body.size());
  if (d.HasParseError() || !d.IsObject() || !d.HasMember("error") || !d["error"].IsObject()) {
    return std::nullopt;
  }
  return stringOr(d["error"], "message");
}

std::optional<int> workersOf(std::string_view healthBody) {
  rapidjson::Document d;
  d.Parse(healthBody.data(), healthBody.size());
  if (d.HasParseError() || !d.IsObject() || !d.HasMember("workers") || !d["workers"].IsInt()) {
    return std::nullopt;
  }
  return d["workers"].GetInt();
}

bool ResultRow::retryable() const {
  if (!error) return false;
  const int s = error->status;
  return s == 0 || s == 429 || s == 499 || s >= 500;
}

std::optional<ResultRow> readResultLine(std::string_view line) {
  rapidjson::Document d;
  d.Parse(line.data(), line.size());
  if (d.HasParseError() || !d.IsObject() || !d.HasMember("key") || !d["key"].IsString()) {
    return std::nullopt;
  }
  ResultRow row;
  row.key = d["key"].GetString();
  row.mesh = stringOr(d, "mesh");
  row.meshPath = stringOr(d, "meshPath");
  row.meshHash = stringOr(d, "meshHash");
  row.label = stringOr(d, "label");
  row.method = stringOr(d, "method");
  row.shading = stringOr(d, "shading");
  row.view = stringOr(d, "view");
  if (d.HasMember("params")) row.params = json::canonical(d["params"]);
  row.size = static_cast<int>(numberOr(d, "size", 0));
  row.supersample = static_cast<int>(numberOr(d, "supersample", 0));
  if (d.HasMember("error") && d["error"].IsObject()) {
    const Value& e = d["error"];
    row.error = ResultError{static_cast<int>(numberOr(e, "status", 0)), stringOr(e, "code"),
                            stringOr(e, "message")};
    return row;
  }
  if (d.HasMember("stats") && d["stats"].IsObject()) {
    row.triangles = numberOr(d["stats"], "triangles", 0);
    row.controlFaces = numberOr(d["stats"], "controlFaces", 0);
  }
  if (d.HasMember("metrics") && d["metrics"].IsObject()) {
    const Value& metrics = d["metrics"];
    for (const auto& group : metrics.GetObject()) {
      if (!group.value.IsObject()) continue;
      for (const auto& m : group.value.GetObject()) {
        if (m.value.IsNumber()) {
          row.metrics[std::string(group.name.GetString()) + "." + m.name.GetString()] =
              m.value.GetDouble();
        }
      }
    }
  }
  if (d.HasMember("timings") && d["timings"].IsObject()) {
    const Value& timings = d["timings"];
    for (const auto& t : timings.GetObject()) {
      if (t.value.IsNumber()) row.timings[t.name.GetString()] = t.value.GetDouble();
    }
  }
  if (d.HasMember("reference") && d["reference"].IsObject()) {
    row.timings["referenceMs"] = numberOr(d["reference"], "referenceMs", 0);
  }
  return row;
}

}  // namespace limn::api
