// The Embree scene of a dense triangle tessellation of the limit surface.
//
// The reference casts its rays against triangles (then moves each hit onto the limit surface);
// this builds that scene: one triangle geometry, robust intersection (no rays slip through
// shared edges, so the coverage of a watertight mesh has no pinholes) and a chosen BVH quality.
#pragma once

#include "render/oracle/embree_device.h"
#include "render/tessellate/triangle_mesh.h"

namespace limn::render::oracle {

// RTC_BUILD_QUALITY_MEDIUM is the default: see oracle_test's timing output for the trade-off.
EmbreeScene buildTriangleScene(const tessellate::TriangleMesh& mesh,
                               RTCBuildQuality quality = RTC_BUILD_QUALITY_MEDIUM);

}  // namespace limn::render::oracle
