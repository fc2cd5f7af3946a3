#include "api/answer.h"

#include <rapidjson/stringbuffer.h>
#include <rapidjson/writer.h>

#include <new>

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
    case render::InputError::Kind::EmptySurface:
      return {422, "empty_surface", error.what(),
              json::detailObject({{"subject", error.subject()}})};
  }
  return {500, "internal", error.what()};
}

Answer answerOrError(const std::string& what, const std::function<Answer()>& work) {
  try {
    try {
      return work();
    } catch (const ApiError& error) {
      return errorAnswer(error);
    } catch (const render::InputError& error) {
      return errorAnswer(fromInputError(error));
    } catch (const render::Cancelled&) {
      return errorAnswer({504, "timeout",
                          "the " + what +
                              " did not finish within the request time limit "
                              "(requestTimeoutMs), or the server is shutting down"});
    } catch (const std::bad_alloc&) {
      return errorAnswer(
          {413, "too_large", "request needs more memory than available", R"({"limit": "memory"})"});
    } catch (const std::exception& error) {
      return errorAnswer({500, "internal", error.what()});
    } catch (...) {
      return errorAnswer({500, "internal", "unknown error"});
    }
  } catch (...) {
    // Building the error answer itself failed (out of memory): a fixed body still answers.
    Answer answer;
    answer.status = 500;
    answer.body = R"({"error":{"code":"internal","message":"out of memory","detail":{}}})";
    return answer;
  }
}

}  // namespace limn::api
