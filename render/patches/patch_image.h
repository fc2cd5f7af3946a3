// The "patches" image: each pixel coloured by the patch it shows. The hue says the patch's
// subdivision level (0 blue, 1 cyan, 2 green, 3 lime, 4 yellow, 5 orange, 6 red, 7 magenta,
// 8 violet); regular patches have the full colour, boundary patches are lighter, crease
// patches darker, and irregular Gregory end caps (always at the isolation level) grey.
#pragma once

#include "render/patches/patch_set.h"
#include "render/patches/patch_tessellation.h"
#include "render/tessellate/triangle_mesh.h"

namespace limn::render::patches {

Vec3f patchColor(const Patch& patch);

// The tessellation with every triangle's corners given their patch's colour (vertices are
// duplicated so that neighbouring patches do not blend).
tessellate::TriangleMesh patchColoredMesh(const PatchMesh& tessellation, const PatchSet& set);

}  // namespace limn::render::patches
