// BatchSpec: what a batch comparison runs — meshes × cameras × methods at one image size —
// as `limn batch SPEC.json` reads it from a file and POST /v1/jobs from a request body, and
// the spec-less form of `limn batch --meshes ... --methods ... --views N`.
//
// Sweeps and camera sets are expanded here, once, into flat lists (methods: one entry per
// parameter combination; views: one per camera), in the order the spec gives them, so every
// process that reads the same spec sees the same rows in the same order (api/batch_plan.h
// numbers them; shards rely on it). Each method and view carries the JSON /v1/compare takes
// for it and a canonical key that names it in results.jsonl, so a later run recognises the
// rows it already has. docs/batch.md describes the format.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "render/pipeline/render_job.h"

namespace limn::api {

// A mesh of the spec: a file, folder or glob (only `limn batch` reads files: a server never
// opens a path it is sent) with an optional scheme, or a mesh given inline / by id.
struct MeshEntry {
  std::string pattern;                // a path or glob ("" for an inline mesh)
  std::optional<std::string> scheme;  // for files: overrides the guess (batch/mesh_files.h)
  std::string name;                   // inline: its name in the results
  std::string meshJson;               // inline: the mesh object as /v1/render takes it
};

// One method with concrete params: one point of a sweep.
struct MethodVariant {
  std::string label;       // "uniform:3" unless the spec names it
  std::string method;      // "uniform"
  std::string paramsJson;  // canonical: keys sorted, e.g. {"level":3}
  std::string shading;     // "smooth", "flat" or "normal-map"

  // {"method", "params", "shading", "label"}: an entry of /v1/compare's "methods".
  std::string compareJson() const;
  // What identifies its rows across runs: method, params and shading (not the label).
  std::string key() const;
};

// One camera, without its image size (the spec's size gives width and height).
struct ViewSpec {
  std::string label;       // "front", "ring 3/8", "random 2 (seed 1)", or the spec's name
  std::string cameraJson;  // canonical camera object, e.g. {"orbit":{"azimuthDeg":45,...}}

  // The camera with "width" and "height" set to `size`.
  std::string compareJson(int size) const;
};

struct BatchSpec {
  std::vector<MeshEntry> meshes;
  std::vector<MethodVariant> methods;
  std::vector<ViewSpec> views;
  int size = 512;       // image width and height, pixels
  int supersample = 4;  // metricSupersample of every row
};

// The JSON spec (docs/batch.md): {"meshes", "methods", "cameras", "size", "supersample"}.
// Throws ApiError (400 invalid_json / invalid_request naming the field, e.g.
// "methods[1].params.level", 413 too_large for a value over `limits`). Each method's params
// are read by /v1/render's reader, so a spec is refused for what /v1/render would refuse.
BatchSpec parseBatchSpec(std::string_view json, const render::pipeline::JobLimits& limits);

// "coarse,uniform:3,adaptive:1,silhouette": a method name with, after a colon, the level of
// uniform, the dicing rate of adaptive (other methods take none). Throws ApiError naming
// `field` (a spec's "methods" entry may be such a list too).
std::vector<MethodVariant> parseMethodList(std::string_view list,
                                           const render::pipeline::JobLimits& limits,
                                           const std::string& field = "--methods");

// `count` orbit views at seeded pseudo-random directions, spread evenly over the sphere's band
// between the elevations (degrees), at the default framing. The generator is limn's own
// (splitmix64), so the views are the same on every machine and library.
std::vector<ViewSpec> seededViews(int count, uint64_t seed, double minElevationDeg = -60,
                                  double maxElevationDeg = 60);

// A folder's index of its meshes, as limn's examples/examples.json is written
// ([{"file": "icosahedron.obj", "scheme": "loop", ...}, ...]): file name -> scheme. Empty for
// text that is not such an index.
std::map<std::string, std::string> schemeIndex(std::string_view json);

// The views a name stands for: front, back, left, right, top, bottom, three-quarter.
std::optional<ViewSpec> namedView(std::string_view name);

}  // namespace limn::api
