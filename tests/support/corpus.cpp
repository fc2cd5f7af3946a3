#include "tests/support/corpus.h"

#include <algorithm>
#include <fstream>
#include <sstream>

#include "formats/obj_reader.h"

#ifndef LIMN_SOURCE_DIR
#error "LIMN_SOURCE_DIR must name the repository"
#endif

namespace limn::testing {

namespace fs = std::filesystem;

fs::path corpusDir() {
  return fs::path(LIMN_SOURCE_DIR) / ".." / "shared" / "corpus" / "osd-shapes";
}

std::vector<fs::path> corpusFiles() {
  std::vector<fs::path> files;
  if (!fs::exists(corpusDir())) return files;
  for (const auto& entry : fs::directory_iterator(corpusDir())) {
    if (entry.path().extension() == ".obj") files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

render::mesh::Scheme corpusScheme(std::string_view fileName) {
  if (fileName.rfind("loop_", 0) == 0) return render::mesh::Scheme::Loop;
  if (fileName.rfind("bilinear_", 0) == 0) return render::mesh::Scheme::Bilinear;
  return render::mesh::Scheme::CatmullClark;
}

std::string readTextFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

std::optional<render::mesh::ControlMesh> readCorpusMesh(
    const fs::path& path, std::optional<render::mesh::Scheme> scheme) {
  if (!fs::exists(path)) return std::nullopt;
  const render::mesh::Scheme chosen = scheme.value_or(corpusScheme(path.filename().string()));
  return formats::readObj(readTextFile(path), chosen, render::mesh::MeshLimits{}).mesh;
}

std::optional<render::mesh::ControlMesh> readCorpusShape(const std::string& name) {
  return readCorpusMesh(corpusDir() / (name + ".obj"));
}

}  // namespace limn::testing
