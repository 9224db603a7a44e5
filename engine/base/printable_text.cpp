#include "engine/base/printable_text.hpp"

#include <cstdint>
#include <cstdio>

namespace bellows {
namespace {

/// Length of the valid UTF-8 sequence starting `text` and its code point, or 0 when it is not one
/// (overlong forms, surrogates and values beyond U+10FFFF included).
std::size_t utf8_sequence(std::string_view text, char32_t& code_point) {
  const auto byte = [&](std::size_t i) { return static_cast<unsigned char>(text[i]); };
  const unsigned char lead = byte(0);
  std::size_t length = 0;
  char32_t value = 0;
  char32_t lowest = 0;
  if (lead >= 0xc2 && lead <= 0xdf) length = 2, value = lead & 0x1fu, lowest = 0x80;
  else if (lead >= 0xe0 && lead <= 0xef) length = 3, value = lead & 0x0fu, lowest = 0x800;
  else if (lead >= 0xf0 && lead <= 0xf4) length = 4, value = lead & 0x07u, lowest = 0x10000;
  else return 0;
  if (text.size() < length) return 0;
  for (std::size_t i = 1; i < length; ++i) {
    if ((byte(i) & 0xc0u) != 0x80u) return 0;
    value = (value << 6) | (byte(i) & 0x3fu);
  }
  if (value < lowest || value > 0x10ffff || (value >= 0xd800 && value <= 0xdfff)) return 0;
  code_point = value;
  return length;
}

}  // namespace

bool is_terminal_control(char32_t c) {
  return c < 0x20 || c == 0x7f || (c >= 0x80 && c <= 0x9f) ||             // C1 controls (CSI, OSC, ...)
         c == 0x061c || c == 0x200e || c == 0x200f ||                     // bidirectional marks
         (c >= 0x202a && c <= 0x202e) || (c >= 0x2066 && c <= 0x2069) ||  // bidirectional overrides
         c == 0x2028 || c == 0x2029 || c == 0xfeff;                       // line and paragraph separators, BOM
}

namespace {

void append_escaped_byte(std::string& out, unsigned char c) {
  switch (c) {
    case '\n':
      out += "\\n";
      return;
    case '\r':
      out += "\\r";
      return;
    case '\t':
      out += "\\t";
      return;
    case 0x1b:
      out += "\\e";
      return;
    default: {
      char escaped[8];
      std::snprintf(escaped, sizeof escaped, "\\x%02x", c);
      out += escaped;
    }
  }
}

}  // namespace

std::string printable(std::string_view text, std::size_t max_bytes) {
  std::string out;
  out.reserve(text.size() < max_bytes ? text.size() : max_bytes);
  std::size_t i = 0;
  while (i < text.size()) {
    const std::size_t before = out.size();
    const auto c = static_cast<unsigned char>(text[i]);
    std::size_t consumed = 1;
    if (c >= 0x20 && c < 0x7f) {
      out += static_cast<char>(c);
    } else if (c < 0x80) {
      append_escaped_byte(out, c);
    } else {
      char32_t code_point = 0;
      const std::size_t length = utf8_sequence(text.substr(i), code_point);
      if (length == 0) {
        append_escaped_byte(out, c);
      } else if (is_terminal_control(code_point)) {
        char escaped[16];
        std::snprintf(escaped, sizeof escaped, "\\u{%04x}", static_cast<unsigned>(code_point));
        out += escaped;
        consumed = length;
      } else {
        out.append(text.substr(i, length));
        consumed = length;
      }
    }
    if (out.size() > max_bytes) {  // this character does not fit: cut before it
      out.resize(before);
      out += "... (" + std::to_string(text.size()) + " bytes)";
      return out;
    }
    i += consumed;
  }
  return out;
}

}  // namespace bellows
