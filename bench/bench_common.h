// What the benchmark programs share: comma-separated flag values, corpus shapes read through
// the real OBJ reader (scheme from the file name's prefix, as the corpus names them), and the
// best of several warm runs of a job.
#pragma once

#include <filesystem>
#include <fstream>
#include <functional>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "formats/obj_reader.h"
#include "render/mesh/control_mesh.h"
#include "render/pipeline/render_job.h"

namespace limn::bench {

inline std::vector<std::string> splitList(const std::string& list) {
  std::vector<std::string> out;
  std::stringstream in(list);
  for (std::string item; std::getline(in, item, ',');) out.push_back(item);
  return out;
}

inline render::mesh::Scheme schemeOfShape(const std::string& name) {
  if (name.rfind("loop_", 0) == 0) return render::mesh::Scheme::Loop;
  if (name.rfind("bilinear_", 0) == 0) return render::mesh::Scheme::Bilinear;
  return render::mesh::Scheme::CatmullClark;
}

// The corpus shape `name` (without .obj) in `dir`, or nothing when the file is not there.
inline std::optional<render::mesh::ControlMesh> readShape(const std::filesystem::path& dir,
                                                          const std::string& name) {
  std::ifstream file(dir / (name + ".obj"));
  if (!file) return std::nullopt;
  std::stringstream text;
  text << file.rdbuf();
  return formats::readObj(text.str(), schemeOfShape(name), {}).mesh;
}

// The fastest (totalMs) of `repeat` runs after a warm-up; `beforeEach` runs before every one
// (e.g. to empty the reference cache so that every run builds its scene).
inline render::pipeline::RenderResult runBest(
    const render::pipeline::RenderJob& job, render::pipeline::RenderContext& context, int repeat,
    const std::function<void()>& beforeEach = [] {}) {
  render::pipeline::JobLimits limits;
  beforeEach();
  render::pipeline::RenderResult best = render::pipeline::run(job, limits, context, {});
  for (int i = 0; i < repeat; ++i) {
    beforeEach();
    render::pipeline::RenderResult r = render::pipeline::run(job, limits, context, {});
    if (r.timings.totalMs < best.timings.totalMs) best = std::move(r);
  }
  return best;
}

}  // namespace limn::bench
