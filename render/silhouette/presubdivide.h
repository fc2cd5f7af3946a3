// Pre-subdivision for the silhouette method: one uniform refinement step of the control mesh,
// so that every edge has at most one extraordinary end and every Catmull-Clark face is a quad.
// The refined mesh has the same limit surface (OpenSubdiv decays semi-sharp creases by one
// level, holes stay holes), so everything measured against the original surface still holds.
#pragma once

#include <string>

#include "render/mesh/control_mesh.h"

namespace limn::render::silhouette {

enum class Presubdivide { Auto, Never, Once };

// Why "auto" refines: a small mesh (under kAutoFaceLimit faces) gains much accuracy for few
// triangles; an edge between two extraordinary vertices, or a non-quad Catmull-Clark face, is
// outside what the contour search and the face triangulation assume.
inline constexpr int kAutoFaceLimit = 500;

// The reason `mesh` should be refined once under "auto", or empty when it need not be.
std::string presubdivisionReason(const mesh::ControlMesh& mesh);

// True when the faces of `mesh` are all quads (Catmull-Clark) or all triangles (Loop): the
// shapes the silhouette method triangulates in their parameter domain.
bool hasSimpleFaces(const mesh::ControlMesh& mesh);

// The mesh after one uniform OpenSubdiv refinement step: positions interpolated, edge and
// vertex sharpness and holes carried over from Far's refined level.
mesh::ControlMesh refineOnce(const mesh::ControlMesh& mesh);

}  // namespace limn::render::silhouette
