// The JSON mesh form with USD's mesh attribute names -> ControlMesh (and back):
//   scheme, points, faceVertexCounts, faceVertexIndices, creaseIndices, creaseLengths,
//   creaseSharpnesses, cornerIndices, cornerSharpnesses, holeIndices, interpolateBoundary,
//   creaseMethod, triangleSubdivision.
// Creases are chains as in USD: crease i runs along creaseLengths[i] consecutive entries of
// creaseIndices (so creaseLengths[i] - 1 edges) with sharpness creaseSharpnesses[i]; when
// creaseSharpnesses has one value per edge instead, each edge takes its own. The mesh is checked
// with validateMesh() before it is returned.
#pragma once

#include <rapidjson/document.h>

#include <string>

#include "render/mesh/control_mesh.h"

namespace limn::api {

// `field` is the object's name in messages ("mesh" -> "mesh.points[3] must be ...").
// Throws ApiError 400 invalid_request for a missing field or a wrong type, and
// render::InputError (InvalidMesh, LimitExceeded) for a mesh that cannot be used.
render::mesh::ControlMesh readJsonMesh(const rapidjson::Value& object, const std::string& field,
                                       const render::mesh::MeshLimits& limits);

// `mesh` in the same form (creases as one 2-vertex chain per edge, each with its sharpness):
// readJsonMesh gives the same mesh back, with the same contentHash.
std::string writeJsonMesh(const render::mesh::ControlMesh& mesh);

// The scheme names of both mesh forms: "catmull-clark" | "loop" | "bilinear" (USD's
// "catmullClark" is accepted too).
render::mesh::Scheme readScheme(const rapidjson::Value& value, const std::string& field);

}  // namespace limn::api
