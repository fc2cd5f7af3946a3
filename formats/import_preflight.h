// Counts a file declares, checked before Assimp allocates for them: a file of a few hundred
// bytes that declares a billion vertices is refused here, not after Assimp reserved the memory.
// Each check is what the file itself must hold to be honest — every declared element needs at
// least some bytes of the file — and the mesh limits where the count is a mesh's.
#pragma once

#include <string_view>

#include "formats/assimp_import.h"

namespace limn::formats {

// PLY (element counts against the bytes after the header and maxVertices / maxFaces), OFF (its
// count line), binary STL (the triangle count against the file's length and maxFaces), glTF and
// GLB (each buffer's byteLength and each accessor's data against the file's length), COLLADA
// (every count="N" attribute against the file's length). FBX and 3DS are left to the checks of
// the scene itself (3DS counts are 16-bit). Throws render::InputError: InvalidMesh ("mesh.data")
// for a count the file cannot hold, LimitExceeded for one over a mesh limit.
void checkDeclaredSizes(std::string_view bytes, ImportFormat format,
                        const render::mesh::MeshLimits& limits);

}  // namespace limn::formats
