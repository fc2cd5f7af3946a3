#include "api/json_util.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <vector>

#include "render/core/quoted.h"

namespace limn::api::json {

std::string describe(const Value& value) {
  switch (value.GetType()) {
    case rapidjson::kNullType:
      return "null";
    case rapidjson::kFalseType:
    case rapidjson::kTrueType:
      return "a boolean";
    case rapidjson::kObjectType:
      return "an object";
    case rapidjson::kArrayType:
      return "an array";
    case rapidjson::kStringType:
      return "a string";
    case rapidjson::kNumberType:
      return "a number";
  }
  return "a value";
}

std::string quote(std::string_view text, size_t maxBytes) { return render::quoted(text, maxBytes); }

std::string formatNumber(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", value);
  return text;
}

std::string detailObject(std::initializer_list<std::pair<const char*, std::string>> members) {
  rapidjson::StringBuffer buffer;
  Writer writer(buffer);
  writer.StartObject();
  for (const auto& [key, value] : members) {
    writeKey(writer, key);
    writeString(writer, value);
  }
  writer.EndObject();
  return buffer.GetString();
}

void fail(const std::string& field, const std::string& message) {
  throw invalidRequest(field, message);
}

void wrongType(const std::string& field, const char* expected, const Value& got) {
  fail(field, field + " must be " + expected + ", got " + describe(got));
}

const Value* find(const Value& object, const char* name) {
  auto it = object.FindMember(name);
  return it == object.MemberEnd() ? nullptr : &it->value;
}

const Value& requireObject(const Value& value, const std::string& field) {
  if (!value.IsObject()) wrongType(field, "an object", value);
  return value;
}

const Value& requireArray(const Value& value, const std::string& field) {
  if (!value.IsArray()) wrongType(field, "an array", value);
  return value;
}

double number(const Value& value, const std::string& field) {
  if (!value.IsNumber()) wrongType(field, "a number", value);
  double d = value.GetDouble();
  if (!std::isfinite(d)) fail(field, field + " must be a finite number");
  return d;
}

int integer(const Value& value, const std::string& field) {
  if (value.IsInt()) return value.GetInt();
  if (value.IsNumber()) {
    double d = value.GetDouble();
    if (std::isfinite(d) && d == std::floor(d) && d >= std::numeric_limits<int>::min() &&
        d <= std::numeric_limits<int>::max()) {
      return static_cast<int>(d);
    }
    fail(field, field + " must be an integer in the range of a 32-bit int");
  }
  wrongType(field, "an integer", value);
}

bool boolean(const Value& value, const std::string& field) {
  if (!value.IsBool()) wrongType(field, "true or false", value);
  return value.GetBool();
}

std::string_view string(const Value& value, const std::string& field) {
  if (!value.IsString()) wrongType(field, "a string", value);
  return {value.GetString(), value.GetStringLength()};
}

render::Vec3 vec3(const Value& value, const std::string& field) {
  if (!value.IsArray() || value.Size() != 3) {
    fail(field, field + " must be an array of 3 numbers, got " +
                    (value.IsArray() ? "an array of " + std::to_string(value.Size()) + " values"
                                     : describe(value)));
  }
  double c[3];
  for (rapidjson::SizeType i = 0; i < 3; ++i) {
    if (!value[i].IsNumber()) fail(field, field + " must be an array of 3 numbers");
    c[i] = number(value[i], field + "[" + std::to_string(i) + "]");
  }
  return {c[0], c[1], c[2]};
}

void writeNumber(Writer& writer, double value) {
  // RapidJSON's Writer refuses NaN and infinity after it has already written the separator,
  // which would leave broken JSON; null is what clients can parse.
  if (std::isfinite(value)) {
    writer.Double(value);
  } else {
    writer.Null();
  }
}

void writeKey(Writer& writer, const char* key) { writer.Key(key); }

namespace {

bool identifierChar(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }

}  // namespace

std::string renameField(std::string text, const std::string& from, const std::string& to) {
  for (size_t at = text.find(from); at != std::string::npos; at = text.find(from, at)) {
    const size_t end = at + from.size();
    const bool whole = (at == 0 || !identifierChar(text[at - 1])) &&
                       (end == text.size() || !identifierChar(text[end]));
    if (!whole) {
      at = end;
      continue;
    }
    text.replace(at, from.size(), to);
    at += to.size();
  }
  return text;
}

void renameField(ApiError& error, const std::string& from, const std::string& to) {
  error.message = renameField(std::move(error.message), from, to);
  error.detailJson = renameField(std::move(error.detailJson), from, to);
}

namespace {

void writeCanonical(Writer& w, const Value& value) {
  if (value.IsObject()) {
    std::vector<const Value::Member*> members;
    for (auto it = value.MemberBegin(); it != value.MemberEnd(); ++it) members.push_back(&*it);
    std::sort(members.begin(), members.end(), [](const Value::Member* a, const Value::Member* b) {
      return std::string_view(a->name.GetString(), a->name.GetStringLength()) <
             std::string_view(b->name.GetString(), b->name.GetStringLength());
    });
    w.StartObject();
    for (const Value::Member* m : members) {
      w.Key(m->name.GetString(), m->name.GetStringLength());
      writeCanonical(w, m->value);
    }
    w.EndObject();
  } else if (value.IsArray()) {
    w.StartArray();
    for (const Value& item : value.GetArray()) writeCanonical(w, item);
    w.EndArray();
  } else if (value.IsNumber()) {
    // 1 and 1.0 are the same value: an integral number is written as an integer.
    const double d = value.GetDouble();
    constexpr double kExactIntegers = 9007199254740992.0;  // 2^53
    if (d == std::floor(d) && std::fabs(d) < kExactIntegers) {
      w.Int64(static_cast<int64_t>(d));
    } else {
      writeNumber(w, d);
    }
  } else {
    value.Accept(w);
  }
}

}  // namespace

std::string canonical(const Value& value) {
  rapidjson::StringBuffer buffer;
  Writer writer(buffer);
  writeCanonical(writer, value);
  return {buffer.GetString(), buffer.GetSize()};
}

void writeString(Writer& writer, std::string_view text) {
  writer.String(text.data(), static_cast<rapidjson::SizeType>(text.size()));
}

void writeStrings(Writer& writer, const std::vector<std::string>& texts) {
  writer.StartArray();
  for (const std::string& text : texts) writeString(writer, text);
  writer.EndArray();
}

}  // namespace limn::api::json
