// Reading the server's JSON answers in integration tests.
#pragma once

#include <rapidjson/document.h>

#include <string>

#include "tests/integration/http_client.h"

namespace limn::testing {

inline rapidjson::Document parseJson(const std::string& text) {
  rapidjson::Document doc;
  doc.Parse(text.c_str(), text.size());
  return doc;
}

// The field a JSON error answer names (error.detail.field), or what the body was instead.
inline std::string errorField(const HttpResponse& r) {
  auto doc = parseJson(r.body);
  if (doc.HasParseError() || !doc.IsObject() || !doc.HasMember("error")) return "<not JSON>";
  const auto& detail = doc["error"]["detail"];
  return detail.HasMember("field") ? detail["field"].GetString() : "<no field>";
}

}  // namespace limn::testing
