// contentHash: a 128-bit digest of everything that defines a control mesh's limit surface
// (scheme, options, points, topology, creases, corners, holes), as 32 hex digits. Two meshes
// with the same digest have the same limit surface; caches key on it.
#pragma once

#include <string>

#include "render/mesh/control_mesh.h"

namespace limn::render::mesh {

std::string contentHash(const ControlMesh& mesh);

}  // namespace limn::render::mesh
