// The shared corpus of OpenSubdiv's regression shapes (../shared/corpus/osd-shapes next to the
// repository; a user's clone may not have it, and tests that need it skip): where it is, the
// scheme each file is meant for (its name's prefix: loop_, bilinear_, else Catmull-Clark), and
// its meshes read by limn's own OBJ reader, so that every tag (creases, corners, holes,
// boundary and crease rules) arrives as the server would read it.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "render/mesh/control_mesh.h"

namespace limn::testing {

std::filesystem::path corpusDir();
// Every .obj of the corpus, sorted by name; empty when there is no corpus.
std::vector<std::filesystem::path> corpusFiles();
render::mesh::Scheme corpusScheme(std::string_view fileName);
std::string readTextFile(const std::filesystem::path& path);

// The mesh in `path` (scheme from its name unless given), read and validated by
// formats::readObj with the default limits; nullopt when the file does not exist. Throws
// render::InputError for a file the reader refuses.
std::optional<render::mesh::ControlMesh> readCorpusMesh(
    const std::filesystem::path& path, std::optional<render::mesh::Scheme> scheme = {});
// corpusDir() / (name + ".obj").
std::optional<render::mesh::ControlMesh> readCorpusShape(const std::string& name);

}  // namespace limn::testing
