// What the console's prompts do with typed text.
#pragma once

#include <cmath>
#include <cstdlib>
#include <string>

#include "engine/base/printable_text.hpp"

namespace bellows::ui {

/// Removes the last UTF-8 code point (Backspace).
inline void pop_last_code_point(std::string& text) {
  while (!text.empty()) {
    const auto byte = static_cast<unsigned char>(text.back());
    text.pop_back();
    if ((byte & 0xC0) != 0x80) break;  // stop after the first byte of a sequence
  }
}

/// "~/x" as $HOME/x, as a shell would (the path prompt is not a shell).
inline std::string expand_home(std::string_view path_text) {
  const std::string path(path_text);
  if (path.rfind("~/", 0) != 0) return path;
  const char* home = std::getenv("HOME");
  return home != nullptr && *home != '\0' ? std::string(home) + path.substr(1) : path;
}

/// A whole finite number ("0.45", "2e-5"): false for anything else, trailing text included.
inline bool parse_number(std::string_view text_view, double& value) {
  const std::string text(text_view);
  if (text.empty()) return false;
  char* end = nullptr;
  value = std::strtod(text.c_str(), &end);
  return end != nullptr && *end == '\0' && std::isfinite(value);
}

}  // namespace bellows::ui
