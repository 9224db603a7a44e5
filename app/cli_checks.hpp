// Checks for numeric command-line options that CLI11's own validators let through: a negative
// number converted into an unsigned seed wraps to 2^64 - 1, and NaN passes every comparison.
#pragma once

#include <cmath>
#include <map>
#include <string>

#include <CLI/CLI.hpp>

namespace bellows {

/// Digits only: a whole number >= 0 that fits 64 bits (CLI11 would wrap "-1" into 2^64 - 1).
inline CLI::Validator unsigned_whole_number() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        if (text.empty() || text.size() > 20 || text.find_first_not_of("0123456789") != std::string::npos) {
          return "must be a whole number from 0 to 18446744073709551615, not '" + text + "'";
        }
        if (text.size() == 20 && text > "18446744073709551615") return "must be at most 18446744073709551615";
        return "";
      },
      "UINT64");
}

/// A finite number of seconds, at least 0 and at most `max_s` (NaN and inf refused).
inline CLI::Validator finite_seconds(double max_s) {
  return CLI::Validator(
      [max_s](std::string& text) -> std::string {
        double value = 0.0;
        std::size_t used = 0;
        try {
          value = std::stod(text, &used);
        } catch (const std::exception&) {
          used = 0;
        }
        if (used != text.size() || text.empty() || !std::isfinite(value) || value < 0.0 || value > max_s) {
          return "must be a finite number of seconds from 0 to " + std::to_string(static_cast<long long>(max_s)) +
                 ", not '" + text + "'";
        }
        return "";
      },
      "SECONDS");
}

/// A word mapped to a value (--rt enforce|try|off): help shows the words, never the mapped codes
/// (CLI11's own description would read "value in {enforce->0,...}").
template <typename Value>
CLI::Validator named_choice(const std::map<std::string, Value>& choices) {
  std::string words;
  for (const auto& [word, value] : choices) words += (words.empty() ? "" : "|") + word;
  CLI::Validator checked = CLI::CheckedTransformer(choices, CLI::ignore_case);
  checked.description(words);
  return checked;
}

}  // namespace bellows
