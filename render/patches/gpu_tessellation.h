// GpuPatchTessellator: a TessellationPlan diced by the GPU's tessellation stages.
//
// Each planned domain is one GL patch of a single vertex. The tessellation control shader sets
// its outer and inner levels from the plan; the fixed-function tessellator makes the pattern
// (equal spacing, so an edge of n segments has its vertices at i/n); the evaluation shader moves
// every vertex on a transition edge to its piece's parameter (the first piece's segments cover
// [0, end0], the next [end0, end1], ...: the same vertices as the finer neighbours'), maps it
// into the patch and evaluates the patch there with Osd's own GLSL patch basis (libosdGPU:
// regular B-spline with boundary masks, Gregory basis, Loop box-spline, Gregory triangle).
// Transform feedback captures the triangles, which come back as a PatchMesh, so the raster
// passes, metrics and the patch image are the CPU path's. Domains are drawn in batches: llvmpipe
// bins all of one draw's primitives before it shades any, and its cost per draw grows faster
// than the patches in it.
//
// The mesh is crack-free by construction of the factors, as the CPU path's, but not welded: each
// triangle has its own three vertices, and the two sides of an edge evaluate its vertices in
// their own patches (in float), so they agree to rounding, not bit for bit.
//
// Needs the calling thread's OpenGL 4.5 context current (a raster::Rasterizer's) whenever it is
// constructed, used or destroyed.
#pragma once

#include <memory>

#include "render/core/cancel.h"
#include "render/patches/patch_set.h"
#include "render/patches/patch_tessellation.h"

namespace limn::render::patches {

struct GpuTessellationStats {
  size_t draws = 0;  // draw calls (batches of domains)
};

class GpuPatchTessellator {
 public:
  // The most domains one draw takes unless told otherwise.
  static constexpr int kDefaultDomainsPerDraw = 1024;

  // Compiles the programs. Throws std::runtime_error when the context has no tessellation
  // stages or not enough storage buffers in them.
  explicit GpuPatchTessellator(int domainsPerDraw = kDefaultDomainsPerDraw);
  ~GpuPatchTessellator();
  GpuPatchTessellator(const GpuPatchTessellator&) = delete;
  GpuPatchTessellator& operator=(const GpuPatchTessellator&) = delete;

  // GL_MAX_TESS_GEN_LEVEL: the most segments an edge may have (plans must keep to it).
  int maxTessLevel() const;

  // The plan's domains of `set` as triangles. `plan` must come from planPatchTessellation() on
  // the same set with maxEdgeFactor <= maxTessLevel(). Checks `cancel` between batches.
  PatchMesh tessellate(const PatchSet& set, const TessellationPlan& plan, const CancelToken& cancel,
                       GpuTessellationStats* stats = nullptr);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace limn::render::patches
