// An HTTP Accept header as a list of media ranges with their q values (RFC 9110 12.5.1), for
// the endpoints that answer more than one media type (/v1/silhouette: JSON or SVG;
// /v1/tessellate: glTF, PLY or OBJ).
#pragma once

#include <optional>
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

// The mesh files /v1/tessellate and /v1/implicit answer (formats/mesh_writers.h writes them).
enum class MeshFormat { Glb, Ply, Obj };

// The format an Accept header ranks highest among model/gltf-binary, application/x-ply (or
// model/ply) and text/plain (or model/obj); an absent header, or one whose best entry is */*,
// gets GLB. Nothing acceptable (e.g. only image/png): nullopt.
std::optional<MeshFormat> chooseMeshFormat(std::string_view accept);
const char* meshMime(MeshFormat format);

}  // namespace limn::api
