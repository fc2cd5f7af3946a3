// Wrong-side pixels: where a drawing shows the other side of the surface than the exact
// reference does. limn shades the front of a surface with an orange albedo and the back with
// a blue one (render/core/shading.h), and specular light adds the same to every channel, so
// the sign of red minus blue tells the side of a covered pixel. A back face or a wrong-sided
// normal showing along a contour (the dark fringes a person sees at once) is a pixel that is
// blue in the drawing and orange in the reference, or the other way round.
#pragma once

#include "render/core/image.h"

namespace limn::testing {

// Along an outline the drawing and the reference can disagree on single grazing pixels, dark
// either way; a fringe a person notices is a band. `inBands` counts the wrong-side pixels with
// at least four wrong-side neighbours (of eight): a line one pixel wide has two.
struct WrongSide {
  long pixels = 0;   // covered in both colour images (RGBA, alpha > 0.5), sides differ
  long inBands = 0;  // of those, the ones with four or more such neighbours
};

// {-1, -1} when the images do not match in size or channels.
WrongSide wrongSidePixels(const render::Image& color, const render::Image& referenceColor);

}  // namespace limn::testing
