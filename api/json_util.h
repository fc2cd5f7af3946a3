// Reading request JSON with errors that name the field ("camera.width must be an integer, got a
// string"), and writing JSON that never holds a non-finite number. Every reader throws ApiError
// 400 invalid_request with {"field": ...} in its detail.
#pragma once

#include <rapidjson/document.h>
#include <rapidjson/stringbuffer.h>
#include <rapidjson/writer.h>

#include <initializer_list>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "api/answer.h"
#include "render/core/vec.h"

namespace limn::api::json {

using Value = rapidjson::Value;
using Writer = rapidjson::Writer<rapidjson::StringBuffer>;

// "a string", "an array", "null", ...: what a value is, for messages.
std::string describe(const Value& value);

// User text echoed in a message: quoted, at most `maxBytes` (cut at a UTF-8 boundary), control
// characters shown as '?'.
std::string quote(std::string_view text, size_t maxBytes = 60);

// A number as people write it in messages ("0.1", "1e+06").
std::string formatNumber(double value);

// A JSON object of string members, e.g. {"field": "camera.width"}.
std::string detailObject(std::initializer_list<std::pair<const char*, std::string>> members);

[[noreturn]] void fail(const std::string& field, const std::string& message);
[[noreturn]] void wrongType(const std::string& field, const char* expected, const Value& got);

// The member `name` of an object, or nullptr when it is absent.
const Value* find(const Value& object, const char* name);

const Value& requireObject(const Value& value, const std::string& field);
const Value& requireArray(const Value& value, const std::string& field);
// A finite number (JSON cannot carry NaN; RapidJSON rejects numbers that overflow a double).
double number(const Value& value, const std::string& field);
// An integral number in int range (3 and 3.0 are both accepted).
int integer(const Value& value, const std::string& field);
bool boolean(const Value& value, const std::string& field);
std::string_view string(const Value& value, const std::string& field);
// [x, y, z] of finite numbers.
render::Vec3 vec3(const Value& value, const std::string& field);

// One of `choices` (by name) or a 400 that lists the valid names.
template <class E>
E choice(const Value& value, const std::string& field,
         std::initializer_list<std::pair<const char*, E>> choices) {
  std::string_view got = string(value, field);
  std::string valid;
  for (const auto& [name, e] : choices) {
    if (got == name) return e;
    valid += (valid.empty() ? "\"" : ", \"") + std::string(name) + "\"";
  }
  fail(field, field + " must be one of " + valid + "; got " + quote(got));
}

// `text` with every `from` that stands as a whole name (not inside a longer one: the "camera"
// of "cameras") replaced by `to`: re-labels an error's message and detail with the place the
// value came from ("camera.width" -> "cameras[2].width").
std::string renameField(std::string text, const std::string& from, const std::string& to);
void renameField(ApiError& error, const std::string& from, const std::string& to);

// `value` as compact JSON with object keys sorted and integral numbers written as integers:
// equal values give equal text, so the text can serve as a key.
std::string canonical(const Value& value);

// A number, or null when it is not finite (JSON has no NaN or infinity).
void writeNumber(Writer& writer, double value);
void writeKey(Writer& writer, const char* key);
void writeString(Writer& writer, std::string_view text);
// ["...", ...]: an answer's "warnings" and other lists of text.
void writeStrings(Writer& writer, const std::vector<std::string>& texts);

}  // namespace limn::api::json
