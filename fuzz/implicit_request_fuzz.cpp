// The whole POST /v1/implicit body, then what the engine does with it before any pixel: the
// field prepared (custom expressions compiled by muparser, their slopes estimated) and
// polygonised on a small grid by the requested method, so hostile expressions, transforms and
// weights reach the polygonisers too.
#include <algorithm>

#include "api/implicit_api.h"
#include "fuzz/fuzz_common.h"
#include "render/implicit/polygonize.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  limn::fuzz::expectOnlyDocumentedErrors([&] {
    limn::api::ImplicitRequest request = limn::api::parseImplicitRequest(
        limn::fuzz::asText(data, size), limn::fuzz::defaultLimits());
    const limn::render::implicit::Field field(request.job.field);
    limn::render::implicit::PolygonizerOptions options = request.job.polygonizer;
    options.resolution = std::clamp(options.resolution, 2, 8);  // each input stays cheap
    options.maxDepth = std::min(options.maxDepth, 1);
    options.maxTriangles = 20'000;
    limn::render::implicit::polygonize(field, options, limn::render::CancelToken{});
  });
  return 0;
}
