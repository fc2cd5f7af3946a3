// An HTTP Accept header as a list of media ranges with their q values (RFC 9110 12.5.1), for
// the endpoints that answer more than one media type (/v1/silhouette: JSON or SVG;
// /v1/tessellate: glTF, PLY or OBJ).
#pragma once

#include <string_view>
#include <vector>

namespace limn::api {

struct MediaRange {
  std::string_view type;  // "image/svg+xml", "model/*", "*/*" (a view into the header)
  double q = 1.0;         // 1 when absent or unreadable
};

std::vector<MediaRange> parseAccept(std::string_view accept);

// ASCII case-insensitive equality (media types are case-insensitive).
bool sameMediaType(std::string_view a, std::string_view b);

}  // namespace limn::api
