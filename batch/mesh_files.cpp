#include "batch/mesh_files.h"

#include <glob.h>

#include <algorithm>
#include <cctype>
#include <fstream>
#include <iterator>
#include <map>
#include <set>

#include "formats/assimp_import.h"

namespace limn::batch {

namespace fs = std::filesystem;

namespace {

bool isGlob(const std::string& pattern) {
  return pattern.find_first_of("*?[") != std::string::npos;
}

// OBJ (limn's reader) or a format Assimp reads ("glb", "ply", ...), by the file's extension;
// "" for anything else.
std::string meshFormatOf(const fs::path& file) {
  std::string extension = file.extension().string();
  if (!extension.empty()) extension.erase(0, 1);
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (extension == "obj" || formats::importFormatNamed(extension)) return extension;
  return "";
}

std::string readText(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw MeshFileError(path.string() + ": cannot be read");
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// The files one pattern stands for, sorted by name. A glob may match nothing (a corpus this
// machine does not have: a warning); a file or folder that is not there is an error.
std::vector<fs::path> filesOf(const std::string& pattern, const fs::path& base,
                              std::vector<std::string>& warnings) {
  fs::path full = fs::path(pattern).is_absolute() ? fs::path(pattern) : base / pattern;
  std::vector<fs::path> files;
  if (isGlob(pattern)) {
    glob_t found{};
    if (::glob(full.c_str(), 0, nullptr, &found) == 0) {
      for (size_t i = 0; i < found.gl_pathc; ++i) {
        if (fs::is_regular_file(found.gl_pathv[i])) files.emplace_back(found.gl_pathv[i]);
      }
    }
    ::globfree(&found);
  } else if (fs::is_directory(full)) {
    for (const auto& entry : fs::directory_iterator(full)) {
      if (entry.is_regular_file() && !meshFormatOf(entry.path()).empty()) {
        files.push_back(entry.path());
      }
    }
  } else if (fs::is_regular_file(full)) {
    files.push_back(full);
  }
  if (files.empty() && isGlob(pattern)) {
    warnings.push_back("no mesh file matches " + pattern + "; left out");
  } else if (files.empty()) {
    throw MeshFileError("meshes: no mesh file matches " + pattern);
  }
  std::sort(files.begin(), files.end());
  return files;
}

// Stems that name more than one different file get their folder in front.
void nameMeshes(std::vector<api::BatchMesh>& meshes) {
  std::map<std::string, int> uses;
  for (const api::BatchMesh& m : meshes) ++uses[m.name];
  for (api::BatchMesh& m : meshes) {
    if (uses[m.name] > 1 && !m.path.empty()) {
      m.name = fs::path(m.path).parent_path().filename().string() + "/" + m.name;
    }
  }
}

}  // namespace

std::string guessScheme(const fs::path& file) {
  const fs::path index = file.parent_path() / "examples.json";
  if (fs::is_regular_file(index)) {
    std::map<std::string, std::string> schemes = api::schemeIndex(readText(index));
    auto it = schemes.find(file.filename().string());
    if (it != schemes.end()) return it->second;
  }
  const std::string name = file.filename().string();
  if (name.rfind("loop_", 0) == 0) return "loop";
  if (name.rfind("bilinear_", 0) == 0) return "bilinear";
  return "catmull-clark";
}

std::vector<api::BatchMesh> loadMeshes(const std::vector<api::MeshEntry>& entries,
                                       const fs::path& base,
                                       const render::pipeline::JobLimits& limits,
                                       std::vector<std::string>& warnings) {
  std::vector<api::BatchMesh> meshes;
  std::set<std::string> hashes;
  auto keep = [&](api::BatchMesh mesh) {
    if (!hashes.insert(mesh.hash).second) {
      warnings.push_back("mesh " + mesh.name + (mesh.path.empty() ? "" : " (" + mesh.path + ")") +
                         " is the same mesh as one listed before; kept once");
      return;
    }
    meshes.push_back(std::move(mesh));
  };
  for (size_t i = 0; i < entries.size(); ++i) {
    const api::MeshEntry& entry = entries[i];
    if (entry.pattern.empty()) {
      std::string name = entry.name.empty() ? "mesh" + std::to_string(i) : entry.name;
      try {
        keep(api::meshFromJson(name, entry.meshJson, limits));
      } catch (const api::ApiError& e) {
        throw MeshFileError("meshes[" + std::to_string(i) + "] (" + name + "): " + e.message);
      }
      continue;
    }
    for (const fs::path& file : filesOf(entry.pattern, base, warnings)) {
      // As the spec wrote it: relative patterns give paths relative to `base`.
      const fs::path shown = fs::path(entry.pattern).is_absolute()
                                 ? file.lexically_normal()
                                 : file.lexically_relative(base).lexically_normal();
      const std::string format = meshFormatOf(file);
      if (format != "obj" && !format.empty()) {
        // Read in this process: `limn batch` on the user's own files (a server's jobs take
        // no paths). The scheme follows the faces unless the spec names one.
        try {
          keep(api::meshFromFile(file.stem().string(), shown.string(), readText(file), format,
                                 entry.scheme, limits));
        } catch (const api::ApiError& e) {
          throw MeshFileError(file.string() + ": " + e.message);
        }
        continue;
      }
      const std::string scheme = entry.scheme.value_or(guessScheme(file));
      try {
        keep(
            api::meshFromObj(file.stem().string(), shown.string(), readText(file), scheme, limits));
      } catch (const api::ApiError& e) {
        throw MeshFileError(file.string() + " (" + scheme + "): " + e.message);
      }
    }
  }
  if (meshes.empty()) throw MeshFileError("meshes: the spec names no mesh that is there");
  nameMeshes(meshes);
  return meshes;
}

}  // namespace limn::batch
