// Shader warm-up for a fresh Rasterizer. llvmpipe compiles each shader variant with LLVM the
// first time a draw uses it (hundreds of milliseconds on a CPU, seconds under load), inside a
// GL call that no cancellation can interrupt. A render worker draws a tiny scene with every
// pass once before it says it is ready, so that this cost is paid at start-up, not by the
// first requests it is given.
#pragma once

#include "render/raster/rasterizer.h"

namespace limn::render::raster {

// Draws a tetrahedron at 16^2 with each pass and shading the pipeline uses (anti-aliased
// colour, mask, depth, normal, wireframe, line overlays, a supersampled mask). Returns false
// when a draw failed: the warm-up only saves time, so a worker goes on without it (its first
// requests compile what is left) rather than being taken out of service.
bool warmUp(Rasterizer& rasterizer) noexcept;

}  // namespace limn::render::raster
