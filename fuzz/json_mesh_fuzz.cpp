// The JSON mesh form (USD names): the request parser's own JSON reading (iterative, so depth
// costs no stack), then readJsonMesh() and validateMesh().
#include <rapidjson/document.h>

#include "api/json_mesh_reader.h"
#include "api/request_parts.h"
#include "fuzz/fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  limn::fuzz::expectOnlyDocumentedErrors([&] {
    rapidjson::Document document;
    limn::api::request::parseJson(limn::fuzz::asText(data, size), document);
    if (!document.IsObject()) return;
    limn::api::readJsonMesh(document, "mesh", limn::fuzz::defaultLimits().mesh);
  });
  return 0;
}
