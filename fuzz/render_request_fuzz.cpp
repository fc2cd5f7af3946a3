// The whole POST /v1/render body: JSON, mesh (both forms), camera, method, params, outputs.
#include "api/render_api.h"
#include "fuzz/fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  limn::fuzz::expectOnlyDocumentedErrors([&] {
    limn::api::parseRenderRequest(limn::fuzz::asText(data, size), limn::fuzz::defaultLimits());
  });
  return 0;
}
