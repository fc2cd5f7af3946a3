// The "cameras" of a batch spec: named views, explicit cameras, orbit rings and seeded random
// sets, each expanded into ViewSpecs (api/batch_spec.h).
#include "api/batch_views.h"

#include <rapidjson/document.h>

#include <cmath>

#include "api/json_util.h"
#include "api/request_parts.h"

namespace limn::api {

namespace {

using json::Value;
using render::pipeline::JobLimits;

constexpr int kMaxViewsPerSet = 1000;  // a ring or a random set

std::string textOf(const Value& value) { return json::canonical(value); }

rapidjson::Document parseText(const std::string& text) {
  rapidjson::Document document;
  document.Parse(text.c_str(), text.size());
  return document;
}

// One decimal of a thousandth of a degree: what the key and the request both carry.
double roundAngle(double degrees) { return std::round(degrees * 1000.0) / 1000.0; }

std::string formatAngle(double degrees) { return json::formatNumber(degrees); }

ViewSpec orbitView(const std::string& label, double azimuthDeg, double elevationDeg,
                   std::optional<double> distance) {
  rapidjson::Document camera(rapidjson::kObjectType);
  auto& a = camera.GetAllocator();
  Value orbit(rapidjson::kObjectType);
  orbit.AddMember("azimuthDeg", roundAngle(azimuthDeg), a);
  orbit.AddMember("elevationDeg", roundAngle(elevationDeg), a);
  if (distance) orbit.AddMember("distance", *distance, a);
  camera.AddMember("orbit", orbit, a);
  return {label.empty() ? "az" + formatAngle(roundAngle(azimuthDeg)) + " el" +
                              formatAngle(roundAngle(elevationDeg))
                        : label,
          textOf(camera)};
}

std::optional<double> optionalDistance(const Value& set, const std::string& field) {
  const Value* v = json::find(set, "distance");
  if (!v) return std::nullopt;
  double d = json::number(*v, field + ".distance");
  if (!(d > 0 && d <= 1e6))
    json::fail(field + ".distance", field + ".distance must be in (0, 1e6]");
  return d;
}

int viewCount(const Value& set, const std::string& field) {
  const Value* v = json::find(set, "count");
  if (!v) json::fail(field + ".count", field + ".count is required");
  int count = json::integer(*v, field + ".count");
  if (count < 1 || count > kMaxViewsPerSet) {
    json::fail(field + ".count", field + ".count must be in 1.." + std::to_string(kMaxViewsPerSet));
  }
  return count;
}

double optionalNumber(const Value& set, const char* key, const std::string& field, double value) {
  const Value* v = json::find(set, key);
  return v ? json::number(*v, field + "." + key) : value;
}

std::vector<ViewSpec> orbitRing(const Value& ring, const std::string& field) {
  json::requireObject(ring, field);
  const int count = viewCount(ring, field);
  const double elevation = optionalNumber(ring, "elevationDeg", field, 0);
  const double start = optionalNumber(ring, "startAzimuthDeg", field, 0);
  if (!(elevation >= -90 && elevation <= 90)) {
    json::fail(field + ".elevationDeg", field + ".elevationDeg must be in -90..90");
  }
  std::optional<double> distance = optionalDistance(ring, field);
  std::vector<ViewSpec> views;
  for (int i = 0; i < count; ++i) {
    views.push_back(orbitView("", start + 360.0 * i / count, elevation, distance));
  }
  return views;
}

std::vector<ViewSpec> randomViews(const Value& set, const std::string& field) {
  json::requireObject(set, field);
  const int count = viewCount(set, field);
  const double seed = optionalNumber(set, "seed", field, 1);
  if (!(seed >= 0 && seed == std::floor(seed) && seed < 9007199254740992.0)) {
    json::fail(field + ".seed", field + ".seed must be a non-negative integer");
  }
  const double lo = optionalNumber(set, "minElevationDeg", field, -60);
  const double hi = optionalNumber(set, "maxElevationDeg", field, 60);
  if (!(lo >= -90 && hi <= 90 && lo <= hi)) {
    json::fail(field, field + ": need -90 <= minElevationDeg <= maxElevationDeg <= 90");
  }
  std::vector<ViewSpec> views = seededViews(count, static_cast<uint64_t>(seed), lo, hi);
  if (std::optional<double> distance = optionalDistance(set, field)) {
    for (ViewSpec& v : views) {
      rapidjson::Document camera = parseText(v.cameraJson);
      camera["orbit"].AddMember("distance", *distance, camera.GetAllocator());
      v.cameraJson = textOf(camera);
    }
  }
  return views;
}

// {"name", "camera"}: any /v1/render camera but its size, which the spec's "size" sets.
ViewSpec explicitView(const Value& entry, const std::string& field, const JobLimits& limits) {
  const Value* camera = json::find(entry, "camera");
  if (!camera)
    json::fail(field + ".camera", field + " needs \"camera\", \"orbitRing\" or \"random\"");
  json::requireObject(*camera, field + ".camera");
  for (const char* side : {"width", "height"}) {
    if (json::find(*camera, side)) {
      json::fail(field + ".camera." + side,
                 field + ".camera." + side + ": the spec's \"size\" sets every view's size");
    }
  }
  std::vector<std::string> warnings;
  try {
    request::parseCamera(*camera, limits, warnings);
  } catch (ApiError& e) {
    json::renameField(e, "camera", field + ".camera");
    throw;
  }
  if (!warnings.empty()) json::fail(field + ".camera", field + ".camera: " + warnings.front());
  std::string label;
  if (const Value* v = json::find(entry, "name")) label = json::string(*v, field + ".name");
  return {label.empty() ? field : label, textOf(*camera)};
}

}  // namespace

std::vector<ViewSpec> parseViewEntry(const Value& entry, const std::string& field,
                                     const JobLimits& limits) {
  if (entry.IsString()) {
    std::optional<ViewSpec> view = namedView(entry.GetString());
    if (!view) {
      json::fail(field, field +
                            " must be one of \"front\", \"back\", \"left\", \"right\", \"top\", "
                            "\"bottom\", \"three-quarter\"; got " +
                            json::quote(entry.GetString()));
    }
    return {*view};
  }
  json::requireObject(entry, field);
  if (const Value* ring = json::find(entry, "orbitRing"))
    return orbitRing(*ring, field + ".orbitRing");
  if (const Value* set = json::find(entry, "random")) return randomViews(*set, field + ".random");
  return {explicitView(entry, field, limits)};
}

std::string ViewSpec::compareJson(int size) const {
  rapidjson::Document camera = parseText(cameraJson);
  camera.AddMember("width", size, camera.GetAllocator());
  camera.AddMember("height", size, camera.GetAllocator());
  return textOf(camera);
}

std::optional<ViewSpec> namedView(std::string_view name) {
  struct Named {
    const char* name;
    double azimuth, elevation;
  };
  static constexpr Named kViews[] = {{"front", 0, 0},          {"back", 180, 0}, {"right", 90, 0},
                                     {"left", 270, 0},         {"top", 0, 90},   {"bottom", 0, -90},
                                     {"three-quarter", 45, 30}};
  for (const Named& v : kViews) {
    if (name == v.name) return orbitView(v.name, v.azimuth, v.elevation, std::nullopt);
  }
  return std::nullopt;
}

std::vector<ViewSpec> seededViews(int count, uint64_t seed, double minElevationDeg,
                                  double maxElevationDeg) {
  // splitmix64 (Steele, Lea, Flood 2014): a fixed, portable sequence for a seed.
  uint64_t state = seed;
  auto next = [&state] {
    uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  };
  auto unit = [&next] { return static_cast<double>(next() >> 11) * 0x1.0p-53; };
  constexpr double kDegrees = 180.0 / 3.14159265358979323846;
  // Uniform in sin(elevation): equal areas of the sphere's band get equally many views.
  const double lo = std::sin(minElevationDeg / kDegrees), hi = std::sin(maxElevationDeg / kDegrees);
  std::vector<ViewSpec> views;
  for (int i = 0; i < count; ++i) {
    const double azimuth = 360.0 * unit();
    const double elevation = std::asin(lo + (hi - lo) * unit()) * kDegrees;
    views.push_back(orbitView("", azimuth, elevation, std::nullopt));
  }
  return views;
}

}  // namespace limn::api
