// The JSON mesh form (USD names): rapidjson parse, then readJsonMesh() and validateMesh().
#include <rapidjson/document.h>

#include "api/json_mesh_reader.h"
#include "fuzz/fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  rapidjson::Document document;
  const std::string_view text = limn::fuzz::asText(data, size);
  document.Parse(text.data(), text.size());
  if (document.HasParseError() || !document.IsObject()) return 0;
  limn::fuzz::expectOnlyDocumentedErrors(
      [&] { limn::api::readJsonMesh(document, "mesh", limn::fuzz::defaultLimits().mesh); });
  return 0;
}
