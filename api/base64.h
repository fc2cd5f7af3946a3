// Base64 (RFC 4648, standard alphabet, '=' padding): how images travel inside JSON answers.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace limn::api {

std::string encodeBase64(const unsigned char* data, size_t size);
inline std::string encodeBase64(const std::vector<unsigned char>& bytes) {
  return encodeBase64(bytes.data(), bytes.size());
}
inline std::string encodeBase64(std::string_view text) {
  return encodeBase64(reinterpret_cast<const unsigned char*>(text.data()), text.size());
}

// The bytes, or nothing when `text` is not padded base64 of the standard alphabet (for tests
// and tools).
std::optional<std::vector<unsigned char>> decodeBase64(std::string_view text);

}  // namespace limn::api
