// The control cage as a line overlay (render/core/overlay.h): every edge of the control mesh
// once, at the control points (not their limit positions), in one dark colour, hidden where
// the drawn surface is in front of it. What outputs: ["cage"] draws over the colour image, so a
// client sees the cage and the smooth surface together.
#pragma once

#include <string>

#include "render/core/overlay.h"
#include "render/mesh/control_mesh.h"

namespace limn::render::tessellate {

inline constexpr std::array<uint8_t, 4> kCageColor = {24, 32, 96, 255};  // dark blue

LineOverlay cageOverlay(const mesh::ControlMesh& cage, const std::string& pass);

}  // namespace limn::render::tessellate
