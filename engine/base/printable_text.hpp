// Text that came from outside (a file, the bus, a message, a name) made safe to echo on a terminal
// or in a one-line error: control bytes cannot move the cursor, retitle the window or hide what
// follows, and a 10 MB field cannot flood the screen. Everything bellows prints that it did not
// write itself goes through printable().
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace bellows {

/// Longest echo of one field (a name, an event's message, a bad CSV line) in messages and tables.
inline constexpr std::size_t kPrintableField = 200;
/// Longest echo of a whole line, e.g. an error message on stderr.
inline constexpr std::size_t kPrintableLine = 4000;

/// `text` with every byte that is not printable UTF-8 escaped: C0 controls and DEL as "\n", "\t",
/// "\r", "\e" or "\xNN"; invalid UTF-8 as "\xNN" per byte; C1 controls, bidirectional overrides and
/// line separators as "\u{NNNN}". Printable UTF-8 (accents, degrees, CJK) is kept as it is.
/// Longer than `max_bytes` once escaped: cut at a character and "... (N bytes)" appended, N being
/// the length of the original.
std::string printable(std::string_view text, std::size_t max_bytes = kPrintableField);

/// True for a code point a terminal acts on or that changes how the rest of a line reads: C0 and
/// C1 controls, DEL, bidirectional marks and overrides, line separators, the byte order mark.
bool is_terminal_control(char32_t code_point);

/// `text` without leading and trailing blanks (spaces, tabs, a CRLF file's carriage return).
constexpr std::string_view trim(std::string_view text) {
  const auto first = text.find_first_not_of(" \t\r");
  if (first == std::string_view::npos) return {};
  return text.substr(first, text.find_last_not_of(" \t\r") - first + 1);
}

}  // namespace bellows
