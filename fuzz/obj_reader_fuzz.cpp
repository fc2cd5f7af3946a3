// The OBJ reader with OpenSubdiv's tag lines: scan, tinyobjloader, tags, validateMesh().
#include "formats/obj_reader.h"
#include "fuzz/fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using limn::render::mesh::Scheme;
  if (size == 0) return 0;
  // The first byte picks the scheme so that Loop's all-triangle rule is reached too.
  const Scheme schemes[] = {Scheme::CatmullClark, Scheme::Loop, Scheme::Bilinear};
  const Scheme scheme = schemes[data[0] % 3];
  limn::fuzz::expectOnlyDocumentedErrors([&] {
    limn::formats::readObj(limn::fuzz::asText(data + 1, size - 1), scheme,
                           limn::fuzz::defaultLimits().mesh);
  });
  return 0;
}
