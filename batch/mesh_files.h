// The meshes a batch spec names, read from disk: a file, a folder (its *.obj files) or a glob
// ("corpus/catmark_*.obj"), each in name order, then the spec's inline meshes as they are.
// Only `limn batch` calls this: a server never opens a path it is sent (POST /v1/jobs takes
// inline meshes only).
#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "api/answer.h"
#include "api/batch_plan.h"
#include "api/batch_spec.h"
#include "render/pipeline/render_job.h"

namespace limn::batch {

// A pattern that matches nothing, a file that cannot be read, or a mesh limn refuses (the
// message names the file and, for a mesh, what /v1/render would have said).
class MeshFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Relative patterns are taken from `base` (the spec file's folder, or the current one for
// --meshes). A glob that matches nothing is left out with a warning (an optional corpus); a
// file or folder that is not there, or no mesh at all, throws MeshFileError. A mesh found twice
// (the same content hash) is kept once, with a warning; meshes whose file names collide are named
// "folder/stem" instead of "stem".
std::vector<api::BatchMesh> loadMeshes(const std::vector<api::MeshEntry>& entries,
                                       const std::filesystem::path& base,
                                       const render::pipeline::JobLimits& limits,
                                       std::vector<std::string>& warnings);

// The scheme of a file the spec gives none for: the one its folder's examples.json lists for it
// (limn's examples/ has one), else by the name's prefix as the OpenSubdiv shapes are named
// ("loop_...", "bilinear_..."), else catmull-clark.
std::string guessScheme(const std::filesystem::path& file);

}  // namespace limn::batch
