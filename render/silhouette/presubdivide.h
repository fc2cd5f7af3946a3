// Pre-subdivision for the silhouette method: one uniform refinement step of the control mesh.
// The method itself needs none: it evaluates every face through Bfr, whatever the valences of
// its edges' ends, and works in a convex domain for every face shape (face_domain.h). Refining
// only buys accuracy inside the faces (their flat chords), which is worth it on small meshes.
// The refined mesh has the same limit surface (OpenSubdiv decays semi-sharp creases by one
// level, holes stay holes), so everything measured against the original surface still holds.
#pragma once

#include <string>

#include "render/core/camera.h"
#include "render/mesh/control_mesh.h"
#include "render/subdiv/limit_surface.h"

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

// Once refined, "auto" refines again (at most kMaxPresubdivisionLevels in all, and only while
// the refined mesh stays under 4 x kAutoFaceLimit faces) while the flat faces are further than
// kMaxChordDeviationPx from the limit surface: a coarse cage of a spiky or strongly curved shape
// (a cube with infinitely sharp corners) leaves chords so far outside the surface that the
// per-face corrections cannot bring them in. Not a fourth level: that would draw as many faces
// as uniform level 4, which the method must stay under.
inline constexpr int kMaxPresubdivisionLevels = 3;
inline constexpr double kMaxChordDeviationPx = 4.0;

// The largest distance, in pixels of `camera` at its depth, between a face's flat piece (its
// corners' limit points, joined bilinearly for quads and linearly for triangles; their mean for
// other faces) and the limit surface, over every face's centre and edge midpoints in view.
double chordDeviationPx(const subdiv::LimitSurface& surface, const Camera& camera);

// The mesh after one uniform OpenSubdiv refinement step: positions interpolated, edge and
// vertex sharpness and holes carried over from Far's refined level.
mesh::ControlMesh refineOnce(const mesh::ControlMesh& mesh);

}  // namespace limn::render::silhouette
