// The whole POST /v1/silhouette body and its Accept header. The input is the header, a
// newline, then the body; with no newline all of it is the body.
#include "api/silhouette_api.h"
#include "fuzz/fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view input = limn::fuzz::asText(data, size);
  const size_t newline = input.find('\n');
  const std::string_view accept = newline == input.npos ? "" : input.substr(0, newline);
  const std::string_view body = newline == input.npos ? input : input.substr(newline + 1);
  limn::fuzz::expectOnlyDocumentedErrors(
      [&] { limn::api::parseSilhouetteRequest(body, accept, limn::fuzz::defaultLimits()); });
  return 0;
}
