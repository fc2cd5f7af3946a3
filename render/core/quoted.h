// User text echoed in a message: in double quotes, at most `maxBytes` (cut at a UTF-8 boundary,
// marked "..."), control characters as '?', so that a message stays one readable line whatever
// a client or a file sent.
#pragma once

#include <string>
#include <string_view>

namespace limn::render {

inline std::string quoted(std::string_view text, size_t maxBytes = 60) {
  const bool cut = text.size() > maxBytes;
  size_t end = cut ? maxBytes : text.size();
  // Never end inside a multi-byte UTF-8 sequence: back up over continuation bytes.
  while (cut && end > 0 && (static_cast<unsigned char>(text[end]) & 0xC0) == 0x80) --end;
  std::string out = "\"";
  for (size_t i = 0; i < end; ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    out += (c < 0x20 || c == 0x7F) ? '?' : static_cast<char>(c);
  }
  out += cut ? "...\"" : "\"";
  return out;
}

}  // namespace limn::render
