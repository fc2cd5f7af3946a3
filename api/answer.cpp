#include "api/answer.h"

#include <rapidjson/stringbuffer.h>
#include <rapidjson/writer.h>

#include "api/json_util.h"

namespace limn::api {

Answer errorAnswer(const ApiError& error) {
  rapidjson::StringBuffer buffer;
  json::Writer writer(buffer);
  writer.StartObject();
  writer.Key("error");
  writer.StartObject();
  writer.Key("code");
  json::writeString(writer, error.code);
  writer.Key("message");
  json::writeString(writer, error.message);
  writer.Key("detail");
  // detailJson is produced by this layer, but a malformed one must not break the body.
  rapidjson::Document detail;
  detail.Parse(error.detailJson.c_str());
  if (!detail.HasParseError() && detail.IsObject()) {
    writer.RawValue(error.detailJson.data(), error.detailJson.size(), rapidjson::kObjectType);
  } else {
    writer.StartObject();
    writer.EndObject();
  }
  writer.EndObject();
  writer.EndObject();

  Answer answer;
  answer.status = error.status;
  answer.body = buffer.GetString();
  return answer;
}

ApiError invalidRequest(const std::string& field, const std::string& message) {
  return {400, "invalid_request", message, json::detailObject({{"field", field}})};
}

ApiError tooLarge(const std::string& limit, const std::string& field, const std::string& message) {
  if (field.empty()) return {413, "too_large", message, json::detailObject({{"limit", limit}})};
  return {413, "too_large", message, json::detailObject({{"limit", limit}, {"field", field}})};
}

ApiError invalidMesh(const std::string& subject, const std::string& message) {
  return {422, "invalid_mesh", message, json::detailObject({{"subject", subject}})};
}

ApiError fromInputError(const render::InputError& error) {
  switch (error.kind()) {
    case render::InputError::Kind::InvalidMesh:
      return invalidMesh(error.subject(), error.what());
    case render::InputError::Kind::LimitExceeded:
      return tooLarge(error.subject(), "", error.what());
    case render::InputError::Kind::InvalidParameter:
      return invalidRequest(error.subject(), error.what());
  }
  return {500, "internal", error.what()};
}

}  // namespace limn::api
