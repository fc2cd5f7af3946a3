#include "api/openapi.h"

#include <cstddef>

namespace limn::api {

namespace detail {
extern const unsigned char kOpenApiBytes[];
extern const std::size_t kOpenApiSize;
}  // namespace detail

std::string_view openApiDocument() {
  return {reinterpret_cast<const char*>(detail::kOpenApiBytes), detail::kOpenApiSize};
}

}  // namespace limn::api
