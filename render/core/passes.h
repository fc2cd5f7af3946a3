// What a renderer (raster or reference) is asked to produce, and how the approximation is shaded.
#pragma once

namespace limn::render {

struct PassSelection {
  bool color = false;
  bool mask = false;
  bool depth = false;
  bool normal = false;
  bool wireframe = false;  // colour with the mesh's edges drawn over it
  int supersample = 0;     // > 0: also fill ImageSet::supersampledMask at this factor
  // Samples per pixel of the colour-like passes (colour, wireframe, line overlays): 1 is one
  // sample at the pixel centre; 4, 8 or 16 are averaged over the pixel (anti-aliased). The mask,
  // depth and normal passes are one sample at the pixel centre either way.
  int antialias = 1;
};

enum class Shading {
  Flat,      // one normal per triangle (the geometric one)
  Smooth,    // interpolated per-vertex normals (limit normals where the method has them)
  NormalMap  // per-pixel normals read from TriangleMesh::normalMap at TriangleMesh::texcoords
};

}  // namespace limn::render
