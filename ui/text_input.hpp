// What the console's prompts do with typed text.
#pragma once

#include <cerrno>
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

enum class NumberParse { kNumber, kNotANumber, kOutOfRange };

/// A whole finite number ("0.45", "2e-5") into `value`: kNotANumber for anything else, trailing text
/// included ("inf" and "nan" too); kOutOfRange for a number a double cannot hold (400 digits, 1e999).
inline NumberParse parse_number(std::string_view text_view, double& value) {
  const std::string text(text_view);
  if (text.empty()) return NumberParse::kNotANumber;
  char* end = nullptr;
  errno = 0;
  value = std::strtod(text.c_str(), &end);
  if (end == nullptr || *end != '\0' || end == text.c_str()) return NumberParse::kNotANumber;
  if (errno == ERANGE || !std::isfinite(value)) {
    // strtod reads "inf" and "nan" as words it knows: those are not numbers an operator typed.
    const bool word = text.find_first_of("iInN") != std::string::npos;
    return word && !std::isfinite(value) && errno != ERANGE ? NumberParse::kNotANumber : NumberParse::kOutOfRange;
  }
  return NumberParse::kNumber;
}

}  // namespace bellows::ui
