#include "api/jobs_api.h"

#include <cstdio>
#include <ctime>

#include "api/batch_spec.h"
#include "api/json_util.h"

namespace limn::api {

BatchPlan parseJobSpec(std::string_view body, const render::pipeline::JobLimits& limits,
                       size_t maxRows, render::mesh::MeshCache* meshes) {
  BatchSpec spec = parseBatchSpec(body, limits);
  std::vector<BatchMesh> read;
  for (size_t i = 0; i < spec.meshes.size(); ++i) {
    const MeshEntry& entry = spec.meshes[i];
    const std::string field = "meshes[" + std::to_string(i) + "]";
    if (!entry.pattern.empty()) {
      json::fail(field, field + " names a file (" + json::quote(entry.pattern) +
                            "); a server reads no files it is sent: give the mesh inline, "
                            "{\"name\": ..., \"mesh\": {...}} (or run limn batch, which reads "
                            "files)");
    }
    try {
      read.push_back(meshFromJson(entry.name.empty() ? "mesh" + std::to_string(i) : entry.name,
                                  entry.meshJson, limits, meshes));
    } catch (ApiError& e) {
      json::renameField(e, "mesh", field + ".mesh");
      throw;
    }
  }
  BatchPlan plan(std::move(spec), std::move(read));
  if (plan.rows().size() > maxRows) {
    throw tooLarge("maxJobRows", "",
                   "the spec has " + std::to_string(plan.rows().size()) +
                       " rows (meshes x cameras x methods): exceeds limit maxJobRows (" +
                       std::to_string(maxRows) + ")");
  }
  return plan;
}

std::string storedSpec(std::string_view body, const BatchPlan& plan) {
  rapidjson::Document spec;
  spec.Parse(body.data(), body.size());  // parseJobSpec read it already
  auto& a = spec.GetAllocator();
  json::Value meshes(rapidjson::kArrayType);
  for (const BatchMesh& mesh : plan.meshes()) {
    rapidjson::Document inline_;
    inline_.Parse(mesh.meshJson.data(), mesh.meshJson.size());
    json::Value entry(rapidjson::kObjectType);
    entry.AddMember("name", json::Value(mesh.name.c_str(), a), a);
    entry.AddMember("mesh", json::Value(inline_, a), a);
    meshes.PushBack(entry, a);
  }
  spec.RemoveMember("meshes");
  spec.AddMember("meshes", meshes, a);
  return json::canonical(spec);
}

namespace {

// "2026-12-03T17:23:03.257Z"
std::string isoTime(int64_t unixMs) {
  const std::time_t seconds = static_cast<std::time_t>(unixMs / 1000);
  std::tm utc{};
  gmtime_r(&seconds, &utc);
  char text[64];
  std::snprintf(text, sizeof text, "%04d-%02d-%02dT%02d:%02d:%02d.%03dZ", utc.tm_year + 1900,
                utc.tm_mon + 1, utc.tm_mday, utc.tm_hour, utc.tm_min, utc.tm_sec,
                static_cast<int>(unixMs % 1000));
  return text;
}

void writeJobObject(json::Writer& w, const JobView& job) {
  const std::string self = "/v1/jobs/" + job.id;
  w.StartObject();
  w.Key("id");
  json::writeString(w, job.id);
  w.Key("state");
  json::writeString(w, job.state);
  w.Key("progress");
  w.StartObject();
  w.Key("done");
  w.Uint64(job.done);
  w.Key("total");
  w.Uint64(job.total);
  w.Key("failed");
  w.Uint64(job.failed);
  w.EndObject();
  w.Key("createdAt");
  json::writeString(w, isoTime(job.createdMs));
  if (job.finishedMs) {
    w.Key("finishedAt");
    json::writeString(w, isoTime(job.finishedMs));
  }
  w.Key("elapsedS");
  json::writeNumber(w, job.elapsedS);
  if (!job.error.empty()) {
    w.Key("error");
    json::writeString(w, job.error);
  }
  w.Key("links");
  w.StartObject();
  w.Key("self");
  json::writeString(w, self);
  w.Key("csv");
  json::writeString(w, self + "/results.csv");
  w.Key("jsonl");
  json::writeString(w, self + "/results.jsonl");
  w.EndObject();
  if (job.withRows) {
    w.Key("offset");
    w.Uint64(job.offset);
    w.Key("rows");
    w.StartArray();
    for (const std::string& row : job.rows) {
      w.RawValue(row.data(), row.size(), rapidjson::kObjectType);
    }
    w.EndArray();
  }
  w.EndObject();
}

}  // namespace

std::string writeJob(const JobView& job) {
  rapidjson::StringBuffer buffer;
  json::Writer w(buffer);
  writeJobObject(w, job);
  return {buffer.GetString(), buffer.GetSize()};
}

std::string writeJobList(const std::vector<JobView>& jobs, const std::string& nextCursor,
                         size_t limit) {
  rapidjson::StringBuffer buffer;
  json::Writer w(buffer);
  w.StartObject();
  w.Key("jobs");
  w.StartArray();
  for (const JobView& job : jobs) writeJobObject(w, job);
  w.EndArray();
  if (!nextCursor.empty()) {
    w.Key("next");
    json::writeString(w, "/v1/jobs?limit=" + std::to_string(limit) + "&after=" + nextCursor);
  }
  w.EndObject();
  return {buffer.GetString(), buffer.GetSize()};
}

std::string withReplica(const std::string& line, const std::string& replica) {
  if (line.size() < 2 || line.front() != '{') return line;
  rapidjson::StringBuffer buffer;
  json::Writer w(buffer);
  json::writeString(w, replica);
  return "{\"replica\":" + std::string(buffer.GetString(), buffer.GetSize()) +
         (line[1] == '}' ? "" : ",") + line.substr(1);
}

}  // namespace limn::api
