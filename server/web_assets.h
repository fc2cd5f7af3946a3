// The files limn serves itself: the web page (web/, at "/") and the example meshes
// (examples/, at "/examples" and "/examples/{name}"). They are compiled into the executable
// (cmake/EmbedFiles.cmake writes the table at configure time), so `limn serve` needs no folder
// next to it and a copied binary serves the same page it was built with.
#pragma once

#include <cstddef>
#include <string_view>

namespace limn::server {

struct EmbeddedFile {
  const char* url;          // "/index.html", "/app.js", "/examples", "/examples/cube"
  const char* contentType;  // "text/html; charset=utf-8", ...
  const unsigned char* bytes;
  std::size_t size;

  std::string_view body() const { return {reinterpret_cast<const char*>(bytes), size}; }
};

// The file served at `path` ("/" is "/index.html"), or null.
const EmbeddedFile* findWebAsset(std::string_view path);

}  // namespace limn::server
