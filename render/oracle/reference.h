// The exact reference: Embree ray casting of the limit surface, used as the oracle every
// approximation is measured against.
//
// Rays are cast against a dense triangle tessellation of the limit surface (finer at outlines,
// so the outline's chord error is about 0.01 output pixels: reference_tessellation.h); every hit
// is then moved onto the true surface at its (face, u, v) by Newton steps on the Bfr surface,
// so depth and normals are exact to about 1e-9 of the model size (surface_hit.h). Shading uses
// the limit normal and render/core/shading.h. The tessellation and its BVH can be kept in a
// ReferenceSceneCache for the next request with the same mesh and camera. For Catmull-Clark
// meshes a second, independent path ray-casts Embree's own subdivision geometry (on request:
// it costs about as much as the reference), and the two masks' disagreement is reported.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "render/core/camera.h"
#include "render/core/cancel.h"
#include "render/core/image.h"
#include "render/core/passes.h"
#include "render/metrics/outline.h"
#include "render/oracle/ray_caster.h"
#include "render/oracle/reference_scene.h"
#include "render/subdiv/limit_surface.h"

namespace limn::render::oracle {

struct ReferenceStats {
  size_t triangles = 0;  // of the dense tessellation
  size_t raysCast = 0;
  size_t newtonFailures = 0;  // hits whose refinement did not converge (kept unrefined)
  double tessellateMs = 0, bvhMs = 0, traceMs = 0;  // 0 for the first two on a cache hit
  size_t outlineFaces = 0;    // faces tessellated finely because they carry an outline
  double outlineErrorPx = 0;  // chord error aimed for at the outline, output pixels
  // A bound on the reference's own outline error, output pixels: the outline's chord error as
  // tessellated (0.01 within the triangle budget; raised when the budget or the rate cap
  // binds). The continuous outline metrics cannot resolve differences below it.
  double accuracyPx = 0;
  size_t hits = 0;           // output pixels covered
  double newtonMs = 0;       // refinement and shading of the hits (traceMs: primary rays only)
  double maskMs = 0;         // the supersampled mask's rays
  double outlineMs = 0;      // locating the outline to sub-pixel precision
  size_t refinedPixels = 0;  // output pixels whose S x S samples were all cast
  bool sceneCached = false;  // the tessellation and BVH came from the cache
};

struct ReferenceResult {
  ImageSet images;
  metrics::Outline outline;  // when asked for (ReferenceOptions::locateOutline)
  // Per output pixel: its S x S mask samples were all cast (elsewhere the mask is uniform over
  // the pixel's block and equal to its neighbours'): where outlines can be, for locateOutline.
  std::vector<char> refinedPixels;
  // The triangles the rays were cast against, so what the reference covers (the silhouette
  // metrics measure distances to it: metrics/coverage_distance.h). Null for implicit surfaces.
  std::shared_ptr<const tessellate::TriangleMesh> coverageMesh;
  ReferenceStats stats;
  std::vector<std::string> warnings;
};

// What the S x S block of each output pixel of a supersampled mask holds: kBlockUncovered,
// kBlockCovered or both bits (mixed). Blocks of several masks (the methods of a comparison)
// merge by OR: a pixel is then "mixed or disagreeing" for the union exactly when it is so for
// one of them, so one reference hinted with the merged blocks is as exact, wherever any of
// those masks has an outline, as a reference hinted with each mask alone.
inline constexpr uint8_t kBlockUncovered = 1, kBlockCovered = 2;
// `supersampledMask` is at `s` times the output size.
std::vector<uint8_t> maskBlocks(const Mask& supersampledMask, int s);
// into |= blocks (into may start empty); blocks of different sizes throw std::invalid_argument.
void mergeMaskBlocks(std::vector<uint8_t>& into, const std::vector<uint8_t>& blocks);

struct ReferenceOptions {
  // A mask at S times the output size (the approximation's): output pixels where its S x S
  // block is not uniform, or disagrees with the reference's own pixel, get all their samples
  // cast too, so the reference's mask is exact wherever either side has an outline.
  const Mask* maskHint = nullptr;
  // The same hint as blocks (maskBlocks, merged over several masks); taken over maskHint.
  const std::vector<uint8_t>* hintBlocks = nullptr;
  bool locateOutline = false;            // needs passes.supersample > 0
  ReferenceSceneCache* cache = nullptr;  // where to find and keep the tessellation and BVH
  // Triangles the dense tessellation aims to stay within (reference_tessellation.h).
  double triangleBudget = kReferenceTriangleBudget;
  // The rasteriser's sample positions for an anti-aliased picture (Rasterizer::samplePositions):
  // with more than one, the colour of pixels along edges is the mean of rays through them, as
  // the rasteriser resolves its samples (antialiasEdges in reference_passes.h).
  std::vector<std::array<float, 2>> colorSamples{};
};

// `passes.supersample` > 0 also fills the supersampled mask. Uses all hardware threads through
// TBB (Embree's), and checks `cancel` between rows of tiles.
//
// Passes follow the rasteriser's conventions: color RGBA (alpha 1 where covered; empty pixels
// are shading::kBackground with alpha 0), mask 1/0, depth linear (0 = empty), normal the unit
// limit normal as oriented by the face winding (not flipped towards the viewer; 0 = empty).
// The wireframe pass of the reference is its color pass: the limit surface has no edges to draw
// (a warning says so). Rays are clipped to the camera's [near, far] like the rasteriser's
// triangles.
//
// The supersampled mask is the dense tessellation's coverage at camera.scaled(S), cast where it
// can differ from the output pixel's own coverage: in every output pixel that has an 8-neighbour
// of other coverage (an outline crossing a pixel's square always leaves some 8-neighbour's
// centre on its other side, unless it is a loop or sliver narrower than a pixel), and where the
// hint says so; elsewhere the pixel's coverage fills its block. A feature thinner than a pixel
// that falls between pixel centres, and that the hint lacks too, is missed (docs/engine.md).
ReferenceResult renderReference(const subdiv::LimitSurface& surface, const Camera& camera,
                                const PassSelection& passes, const CancelToken& cancel,
                                const ReferenceOptions& options = {});

// renderReference in two halves, so that the first can run while the approximation it will be
// compared with is drawn: beginReference does all that needs no hint (the scene, cached or
// built; the primary rays; the shaded passes) and ignores options.maskHint and hintBlocks;
// finishReference casts the supersampled mask (with the hint) and locates the outline.
// renderReference(..) is finishReference(beginReference(..), ..) with the same arguments.
struct BegunReference {
  ReferenceResult result;
  std::shared_ptr<const ReferenceScene> scene;
  std::vector<PixelHit> hits;  // of the primary rays, row-major
};
BegunReference beginReference(const subdiv::LimitSurface& surface, const Camera& camera,
                              const PassSelection& passes, const CancelToken& cancel,
                              const ReferenceOptions& options = {});
ReferenceResult finishReference(BegunReference begun, const Camera& camera,
                                const PassSelection& passes, const CancelToken& cancel,
                                const ReferenceOptions& options = {});

// The outline of any triangle mesh (an approximation) seen by `camera`, located to sub-pixel
// precision by rays against its own triangles; `supersampledMask` (its coverage at S times the
// size, e.g. from the rasteriser) says where to look.
// `scan`: the reference's refinedPixels when that reference was hinted with this mask (then they
// hold every place this mask can be mixed), or null to look everywhere.
metrics::Outline locateMeshOutline(const tessellate::TriangleMesh& mesh, const Camera& camera,
                                   const Mask& supersampledMask, int supersample,
                                   const CancelToken& cancel,
                                   const std::vector<char>* scan = nullptr);

// The independent check (Catmull-Clark only): Embree's RTC_GEOMETRY_TYPE_SUBDIVISION with the
// mesh's creases and corners, cast at `camera` (pass the supersampled one); returns its coverage
// mask, or nothing with a reason in `whyNot` where Embree cannot represent the surface as
// OpenSubdiv defines it: Loop or bilinear schemes, Chaikin creases, smooth triangle subdivision,
// faces over 15 vertices, non-manifold topology, and two crease configurations where Embree's
// rules were measured to differ from Far's limit by 2-15% of the model size (creases of
// different sharpness meeting at a vertex with one of them semi-sharp; semi-sharp corners),
// and interior vertices of valence 2.
// Holes and the faces boundary None removes stay in Embree's mesh (they support their
// neighbours, as in OpenSubdiv) and are skipped by a filter; boundary modes map to Embree's
// smooth boundary or pinned corners. Embree's grid is uniform over the mesh, sized from the
// chord error, and zero-width cracks between its patches are closed by re-casting. Measured
// agreement with the reference on the corpus: at most one supersampled pixel apart, mean
// 0.0002-0.004 output px; Embree is off by about 3e-4 of the model size near infinitely sharp
// crease ends and cuts infinitely sharp corner tips short by a pixel or two.
//
// With `outline`, also locates the outline of Embree's surface to sub-pixel precision (rays on
// its own scene): `camera` must then be an output camera scaled by `supersample`, and the
// outline is in that output camera's pixels.
std::optional<Mask> embreeSubdivisionMask(const subdiv::LimitSurface& surface, const Camera& camera,
                                          const CancelToken& cancel, std::string* whyNot,
                                          int supersample = 1, metrics::Outline* outline = nullptr);

}  // namespace limn::render::oracle
