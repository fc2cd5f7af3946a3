// BatchPlan: a batch spec's meshes, views and methods as one numbered list of rows, and the
// /v1/compare requests that compute them.
//
// The row list is deterministic: meshes in the order the spec resolves them, then views, then
// methods (row index = (mesh * views + view) * methods + method), so every process that reads
// the same spec and files numbers the rows alike. That is what sharding relies on: shard K of N
// takes the rows whose index % N == K. Each row has a key — the mesh's content hash, the
// method's key, the view's camera, the size and the supersampling — which names it in
// results.jsonl: a row whose key is there already is not computed again (resume), wherever the
// file was moved and whatever the mesh file is called now.
//
// Rows are computed in groups, one per (mesh, view) of consecutive rows: one /v1/compare
// request with the group's methods, so the reference of a view is built once per group.
#pragma once

#include <cstddef>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "api/batch_spec.h"
#include "render/mesh/mesh_cache.h"
#include "render/pipeline/render_job.h"

namespace limn::api {

// A mesh of the batch, read and validated.
struct BatchMesh {
  std::string name;      // in the results: the file's stem, or the spec's name
  std::string path;      // the file it was read from ("" when given inline)
  std::string hash;      // render::mesh::contentHash: the rows' key
  std::string meshJson;  // the "mesh" object of the /v1/compare requests
  int vertices = 0, faces = 0;
};

// An OBJ file's text as a batch mesh (`scheme`: "catmull-clark", "loop" or "bilinear"),
// checked against `limits` as /v1/render would. Throws ApiError (422 naming the line...).
BatchMesh meshFromObj(const std::string& name, const std::string& path, const std::string& text,
                      const std::string& scheme, const render::pipeline::JobLimits& limits);
// A mesh file Assimp reads (`format`: "glb", "ply", ... as formats::importFormatNamed takes),
// its scheme the given one, else chosen from its faces (formats/assimp_import.h); the compare
// requests carry the file itself (dataBase64), so each worker reads it as /v1/render would.
// Throws ApiError (422 naming the format and Assimp's message, 413 over a limit).
BatchMesh meshFromFile(const std::string& name, const std::string& path, const std::string& bytes,
                       const std::string& format, const std::optional<std::string>& scheme,
                       const render::pipeline::JobLimits& limits);
// A mesh given inline in a spec (either /v1/render form, or {"id"} of a mesh in `meshes`, which
// the result carries inline: meshJson never refers to a cache).
BatchMesh meshFromJson(const std::string& name, const std::string& meshJson,
                       const render::pipeline::JobLimits& limits,
                       render::mesh::MeshCache* meshes = nullptr);

struct BatchRow {
  size_t index = 0;  // in the whole row list
  size_t mesh = 0, view = 0, method = 0;
  std::string key;
};

// Which part of the rows one process takes (index % count == index).
struct Shard {
  int index = 0, count = 1;
};

// The rows of one (mesh, view): one /v1/compare request.
struct RowGroup {
  size_t mesh = 0, view = 0;
  std::vector<size_t> rows;  // indices into BatchPlan::rows()
};

class BatchPlan {
 public:
  BatchPlan(BatchSpec spec, std::vector<BatchMesh> meshes);

  const BatchSpec& spec() const { return spec_; }
  const std::vector<BatchMesh>& meshes() const { return meshes_; }
  const std::vector<BatchRow>& rows() const { return rows_; }

  // The rows of `shard` whose keys are not in `done`, grouped by (mesh, view) in row order;
  // a group holds at most `maxRowsPerGroup` rows (the server's maxCompareRows).
  std::vector<RowGroup> pendingGroups(const Shard& shard, const std::set<std::string>& done,
                                      size_t maxRowsPerGroup) const;

  // The /v1/compare body of a group: its mesh, its view at the spec's size, its methods, the
  // spec's supersampling, no images.
  std::string compareBody(const RowGroup& group) const;

 private:
  BatchSpec spec_;
  std::vector<BatchMesh> meshes_;
  std::vector<BatchRow> rows_;
};

// A row's key: "<mesh hash> <method key> <camera> <size>px S<supersample>".
std::string rowKey(const BatchMesh& mesh, const MethodVariant& method, const ViewSpec& view,
                   int size, int supersample);

}  // namespace limn::api
