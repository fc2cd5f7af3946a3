#include "server/web_assets.h"

namespace limn::server {

// Defined in the generated web_assets_data.cpp.
extern const EmbeddedFile kEmbeddedFiles[];
extern const std::size_t kEmbeddedFileCount;

const EmbeddedFile* findWebAsset(std::string_view path) {
  if (path == "/") path = "/index.html";
  for (std::size_t i = 0; i < kEmbeddedFileCount; ++i) {
    if (path == kEmbeddedFiles[i].url) return &kEmbeddedFiles[i];
  }
  return nullptr;
}

}  // namespace limn::server
