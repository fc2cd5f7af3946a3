// Pre-subdivision for the silhouette method: one uniform refinement step of the control mesh.
// The method itself needs none: it evaluates every face through Bfr, whatever the valences of
// its edges' ends, and works in a convex domain for every face shape (face_domain.h). Refining
// only buys accuracy inside the faces (their flat chords), which is worth it on small meshes.
// The refined mesh has the same limit surface (OpenSubdiv decays semi-sharp creases by one
// level, holes stay holes), so everything measured against the original surface still holds.
#pragma once

#include <string>

#include "render/mesh/control_mesh.h"

namespace limn::render::silhouette {

enum class Presubdivide { Auto, Never, Once };

// Why "auto" refines a mesh of under kAutoFaceLimit faces and no other: there, the refined
// mesh's triangles are a few percent of the equally accurate uniform level's (6 faces: 620
// triangles against uniform level 5's 12,288), and its flat chords shade far better. Above it
// the coarse faces are small already, and refining everything would quadruple the triangles
// away from the contour too (bench/silhouette_views_results.md measures both).
inline constexpr int kAutoFaceLimit = 500;

// The reason `mesh` should be refined once under "auto", or empty when it need not be.
std::string presubdivisionReason(const mesh::ControlMesh& mesh);

// The mesh after one uniform OpenSubdiv refinement step: positions interpolated, edge and
// vertex sharpness and holes carried over from Far's refined level.
mesh::ControlMesh refineOnce(const mesh::ControlMesh& mesh);

}  // namespace limn::render::silhouette
