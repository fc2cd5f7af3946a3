#include "api/jobs_api.h"

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

std::string writeJob(const JobView& job) {
  rapidjson::StringBuffer buffer;
  json::Writer w(buffer);
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
  w.Key("elapsedS");
  json::writeNumber(w, job.elapsedS);
  if (!job.error.empty()) {
    w.Key("error");
    json::writeString(w, job.error);
  }
  w.Key("offset");
  w.Uint64(job.offset);
  w.Key("rows");
  w.StartArray();
  for (const std::string& row : job.rows) {
    w.RawValue(row.data(), row.size(), rapidjson::kObjectType);
  }
  w.EndArray();
  w.EndObject();
  return {buffer.GetString(), buffer.GetSize()};
}

}  // namespace limn::api
