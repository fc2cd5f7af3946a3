// The Embree scene of a dense triangle tessellation of the limit surface.
//
// The reference casts its rays against triangles (then moves each hit onto the limit surface);
// this builds that scene: one triangle geometry, robust intersection (no rays slip through
// shared edges, so the coverage of a watertight mesh has no pinholes) and a chosen BVH quality.
#pragma once

#include <cstdint>
#include <vector>

#include "render/oracle/embree_device.h"
#include "render/tessellate/triangle_mesh.h"

namespace limn::render::oracle {

// Measured on 0.8M triangles, 2 threads (best of 4): build / 1024^2 closest hits / 4096^2
// occlusion rays: LOW 39 / 54 / 496 ms, MEDIUM 158 / 52 / 396 ms, HIGH 138 / 46 / 393 ms. The
// reference now casts the supersampled mask only near outlines (about 0.1M rays at 1024^2), so
// every caller builds at LOW; HIGH would pay only for full 4096^2 casts.
// `only` (optional): the triangles to put in the scene, by index; every triangle otherwise.
EmbreeScene buildTriangleScene(const tessellate::TriangleMesh& mesh, RTCBuildQuality quality,
                               const std::vector<uint32_t>* only = nullptr);

}  // namespace limn::render::oracle
