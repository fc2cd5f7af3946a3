// The camera of a request body (request_parts.h): every field optional, each checked with a
// message naming it; and the checks that need the surface's size.
#include <algorithm>
#include <cmath>
#include <initializer_list>

#include "api/json_util.h"
#include "api/request_parts.h"

namespace limn::api::request {

namespace {

using json::Value;
using render::pipeline::JobLimits;

int imageSide(const Value& value, const std::string& field, const JobLimits& limits) {
  int side = json::integer(value, field);
  if (side < 1) json::fail(field, field + " must be at least 1, got " + std::to_string(side));
  if (side > limits.maxImageSide) {
    throw tooLarge("maxImageSide", field,
                   field + " " + std::to_string(side) + " exceeds limit maxImageSide (" +
                       std::to_string(limits.maxImageSide) + ")");
  }
  return side;
}

render::Orbit parseOrbit(const Value& orbit, std::vector<std::string>& warnings) {
  json::requireObject(orbit, "camera.orbit");
  warnUnknownFields(orbit, "camera.orbit", {"azimuthDeg", "elevationDeg", "distance"}, warnings);
  render::Orbit out;
  if (const Value* v = json::find(orbit, "azimuthDeg")) {
    out.azimuthDeg = json::number(*v, "camera.orbit.azimuthDeg");
  }
  if (const Value* v = json::find(orbit, "elevationDeg")) {
    out.elevationDeg = json::number(*v, "camera.orbit.elevationDeg");
    if (!(out.elevationDeg >= -90 && out.elevationDeg <= 90)) {
      json::fail("camera.orbit.elevationDeg",
                 "camera.orbit.elevationDeg must be between -90 and 90, got " +
                     json::formatNumber(out.elevationDeg));
    }
  }
  if (const Value* v = json::find(orbit, "distance")) {
    out.distance = json::number(*v, "camera.orbit.distance");
    if (!(*out.distance > 0)) {
      json::fail("camera.orbit.distance",
                 "camera.orbit.distance (in bounding-sphere radii) must be > 0, got " +
                     json::formatNumber(*out.distance));
    }
  }
  return out;
}

}  // namespace

render::CameraSpec parseCamera(const Value& camera, const JobLimits& limits,
                               std::vector<std::string>& warnings) {
  json::requireObject(camera, "camera");
  warnUnknownFields(
      camera, "camera",
      {"eye", "orbit", "target", "up", "fovYDeg", "projection", "orthoHeight", "width", "height"},
      warnings);
  render::CameraSpec spec;
  if (const Value* v = json::find(camera, "eye")) spec.eye = json::vec3(*v, "camera.eye");
  if (const Value* v = json::find(camera, "orbit")) {
    if (spec.eye) {
      json::fail("camera.orbit",
                 "camera.orbit and camera.eye are two ways to place the eye; give one");
    }
    spec.orbit = parseOrbit(*v, warnings);
  }
  if (const Value* v = json::find(camera, "target")) spec.target = json::vec3(*v, "camera.target");
  if (const Value* v = json::find(camera, "up")) {
    spec.up = json::vec3(*v, "camera.up");
    if (render::length(*spec.up) == 0) json::fail("camera.up", "camera.up must not be zero");
  }
  if (const Value* v = json::find(camera, "fovYDeg")) {
    double fov = json::number(*v, "camera.fovYDeg");
    // Below a thousandth of a degree the projection's scale leaves float range.
    if (!(fov >= 1e-3 && fov <= 179.9)) {
      json::fail("camera.fovYDeg", "camera.fovYDeg must be between 0.001 and 179.9");
    }
    spec.fovYDeg = fov;
  }
  if (const Value* v = json::find(camera, "projection")) {
    spec.projection =
        json::choice<render::Projection>(*v, "camera.projection",
                                         {{"perspective", render::Projection::Perspective},
                                          {"orthographic", render::Projection::Orthographic}});
  }
  if (const Value* v = json::find(camera, "orthoHeight")) {
    double h = json::number(*v, "camera.orthoHeight");
    if (!(h > 0)) json::fail("camera.orthoHeight", "camera.orthoHeight must be > 0");
    spec.orthoHeight = h;
  }
  if (const Value* v = json::find(camera, "width")) {
    spec.width = imageSide(*v, "camera.width", limits);
  }
  if (const Value* v = json::find(camera, "height")) {
    spec.height = imageSide(*v, "camera.height", limits);
  }
  return spec;
}

void checkCameraAgainstMesh(const render::CameraSpec& camera,
                            const render::mesh::ControlMesh& mesh) {
  checkCameraAgainstBounds(camera, mesh.bounds());
}

void checkCameraAgainstBounds(const render::CameraSpec& camera, const render::Bounds& bounds) {
  const render::Vec3 centre = bounds.center();
  // The rasteriser's float precision is relative to the mesh's size: a camera a million radii
  // away (or an orthographic view a million times larger or smaller than the mesh) cannot be
  // drawn meaningfully, and its tessellation estimates degenerate.
  constexpr double kMaxScale = 1e6;
  const double radius = std::max(bounds.diagonal() / 2, 1e-12);
  auto checkDistance = [&](const std::optional<render::Vec3>& point, const char* field) {
    if (point && render::length(*point - centre) > kMaxScale * radius) {
      json::fail(field, std::string(field) + " is more than 1e6 bounding radii (" +
                            json::formatNumber(radius) + ") from the surface's centre");
    }
  };
  checkDistance(camera.eye, "camera.eye");
  checkDistance(camera.target, "camera.target");
  if (camera.orbit && camera.orbit->distance && *camera.orbit->distance > kMaxScale) {
    json::fail("camera.orbit.distance",
               "camera.orbit.distance is more than 1e6 bounding radii (it is in radii)");
  }
  if (camera.orthoHeight &&
      !(*camera.orthoHeight <= kMaxScale * radius && *camera.orthoHeight >= radius / kMaxScale)) {
    json::fail("camera.orthoHeight",
               "camera.orthoHeight must be within 1e6 times the surface's "
               "bounding radius (" +
                   json::formatNumber(radius) + ")");
  }
  // The view needs a direction: an eye on the target (given, or the mesh's centre) has none.
  if (camera.eye) {
    render::Vec3 target = camera.target.value_or(centre);
    if (render::length(*camera.eye - target) == 0) {
      json::fail("camera.eye", "camera.eye is at the camera target: the view has no direction");
    }
  }
}

}  // namespace limn::api::request
