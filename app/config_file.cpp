#include "app/config_file.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <fstream>
#include <vector>
#include <set>
#include <sstream>

#include <toml++/toml.h>

#include "devices/simulated_arm.hpp"
#include "engine/base/errors.hpp"
#include "engine/base/printable_text.hpp"
#include "sessions/file_access.hpp"

namespace bellows {
namespace {

// A lab's configuration is a few kilobytes of `[section] key = value`. These bounds are checked
// before toml++ sees the text: its parser recurses once per nesting level, and a file nested tens
// of thousands of levels deep (`[a.a.a...]`, `x = [[[[...`) overflows the stack.
constexpr std::size_t kMaxConfigBytes = kMaxConfigFileBytes;
constexpr int kMaxTomlNesting = 16;

// The deepest nesting in TOML text: open arrays and inline tables plus the dots of a dotted key or
// table header. Strings and comments are skipped; a value's decimal point counts as a dot, which
// only makes the estimate a little high.
void check_toml_nesting(const std::string& text, const std::string& source_name) {
  int brackets = 0, dots = 0, line = 1;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '#') {
      while (i + 1 < text.size() && text[i + 1] != '\n') ++i;
    } else if (c == '"' || c == '\'') {
      const bool multiline = text.compare(i, 3, std::string(3, c)) == 0;
      const std::string close = multiline ? std::string(3, c) : std::string(1, c);
      for (i += close.size(); i < text.size() && text.compare(i, close.size(), close) != 0; ++i) {
        if (c == '"' && text[i] == '\\') ++i;  // an escaped character, perhaps a quote
        if (i < text.size() && text[i] == '\n') {
          if (!multiline) break;  // unterminated: toml++ reports it
          ++line;
        }
      }
      if (multiline) i += 2;
    } else if (c == '[' || c == '{') {
      ++brackets;
      dots = 0;
    } else if (c == ']' || c == '}') {
      if (brackets > 0) --brackets;
      dots = 0;
    } else if (c == '.') {
      ++dots;
    } else if (c == '=' || c == ',' || c == '\n') {
      dots = 0;
      if (c == '\n') ++line;
    }
    if (brackets + dots > kMaxTomlNesting) {
      throw InputError("config " + source_name + ":" + std::to_string(line) + ": nested deeper than " +
                       std::to_string(kMaxTomlNesting) + " levels (a configuration is [section] key = value)");
    }
  }
}

// The shortest decimal that reads back as exactly `value`, always a TOML float ("2.0", "1e-06").
std::string shortest_exact(double value) {
  std::array<char, 32> digits{};
  const auto [end, error] = std::to_chars(digits.data(), digits.data() + digits.size(), value);
  std::string text(digits.data(), error == std::errc() ? end : digits.data());
  if (text.find_first_of(".eEn") == std::string::npos) text += ".0";  // n: nan, inf (never valid here)
  return text;
}

/// "[controller] filter_samples" for the key assigned on line `line` (1-based) of `text`: what a
/// TOML parse error there is about (a value out of range, a bad number) names the key the docs
/// promise. Empty when that line assigns no key.
std::string key_at_line(const std::string& text, std::size_t line) {
  std::istringstream lines(text);
  std::string current, section;
  for (std::size_t n = 1; std::getline(lines, current) && n <= line; ++n) {
    const std::size_t start = current.find_first_not_of(" \t");
    if (start == std::string::npos || current[start] == '#') continue;
    if (current[start] == '[') {
      const std::size_t end = current.find(']', start);
      if (end != std::string::npos) section = current.substr(start, end - start + 1);
      continue;
    }
    if (n != line) continue;
    const std::size_t equals = current.find('=', start);
    if (equals == std::string::npos) return "";
    std::string key = current.substr(start, equals - start);
    while (!key.empty() && (key.back() == ' ' || key.back() == '\t')) key.pop_back();
    if (key.empty()) return "";
    return section.empty() ? key : section + " " + key;
  }
  return "";
}

}  // namespace

void apply_config_toml(const std::string& toml_text, const std::string& source_name, Configuration& config) {
  if (toml_text.size() > kMaxConfigBytes) {
    throw InputError("config " + source_name + ": larger than " + std::to_string(kMaxConfigBytes) +
                     " bytes (a configuration is a few kilobytes)");
  }
  check_toml_nesting(toml_text, source_name);
  toml::table root;
  try {
    root = toml::parse(toml_text, source_name);
  } catch (const toml::parse_error& error) {
    std::ostringstream where;
    where << source_name << ":" << error.source().begin.line << ":" << error.source().begin.column << ": ";
    if (const std::string key = key_at_line(toml_text, error.source().begin.line); !key.empty()) {
      where << printable(key, kPrintableField) << ": ";
    }
    where << error.description();
    throw InputError("config " + where.str());
  }
  const auto& bindings = parameter_bindings();
  std::set<std::string> sections;
  for (const ParameterBinding& b : bindings) sections.insert(b.section);

  for (const auto& [section_key, section_node] : root) {
    const std::string section(section_key.str());
    if (!sections.count(section)) {
      throw InputError("config " + source_name + ": unknown section [" + section + "]");
    }
    const toml::table* table = section_node.as_table();
    if (table == nullptr) throw InputError("config " + source_name + ": [" + section + "] must be a table");
    for (const auto& [key_node, value] : *table) {
      const std::string key(key_node.str());
      const ParameterBinding* binding = find_parameter(section, key);
      const std::string where = "config " + source_name + ": [" + section + "] " + key;
      if (binding == nullptr) throw InputError(where + ": unknown key");
      try {
        if (binding->text) {
          if (!value.is_string()) throw InputError(where + ": expected a string");
          *binding->text(config) = *value.value<std::string>();
          // The simulated arm's faults are the devices layer's, out of the configuration layer's sight.
          if (section == "plant" && key == "fault") {
            try {
              simulated_fault_from_string(*binding->text(config));
            } catch (const InputError& error) {
              throw InputError(where + ": " + error.what());
            }
          }
        } else if (binding->integer) {
          if (!value.is_integer()) throw InputError(where + ": expected a whole number in " + binding->range.text());
          const std::int64_t whole = *value.value<std::int64_t>();
          check_parameter_value(*binding, static_cast<double>(whole));  // before the int: nothing wraps
          *binding->integer(config) = static_cast<int>(whole);
        } else {
          if (!value.is_number()) throw InputError(where + ": expected a number in " + binding->range.text());
          const double number = *value.value<double>();
          check_parameter_value(*binding, number);
          *binding->real(config) = number;
        }
      } catch (const InputError& error) {
        const std::string what = error.what();
        throw InputError(what.rfind("config ", 0) == 0 ? what : "config " + source_name + ": " + what);
      }
    }
  }
  try {
    validate_configuration(config);
  } catch (const InputError& error) {
    throw InputError("config " + source_name + ": " + error.what());
  }
  // The plant and the controller share one ambient pressure and temperature.
  config.controller.gas = config.plant.gas;
}

Configuration load_config_file(const std::string& path) {
  // A directory, FIFO or device is refused (never read as an empty file, never waited on).
  const std::string text = read_regular_file(path, kMaxConfigBytes, "config");
  Configuration config;
  apply_config_toml(text, path, config);
  return config;
}

std::string config_to_toml(const Configuration& config) {
  Configuration copy = config;
  // Sections in the table's order (the order of docs/configuration.md), each key under a comment
  // with its meaning, unit and range; numbers in their shortest exact form (0.4, not 0.40000000000000002).
  std::vector<std::string> sections;
  for (const ParameterBinding& b : parameter_bindings()) {
    if (std::find(sections.begin(), sections.end(), b.section) == sections.end()) sections.push_back(b.section);
  }
  std::ostringstream out;
  out << "# bellows configuration: every key with its value. Keep only the keys you change.\n";
  for (const std::string& section : sections) {
    out << "\n[" << section << "]\n";
    for (const ParameterBinding& b : parameter_bindings()) {
      if (b.section != section) continue;
      out << "# " << b.description;
      if (!b.unit.empty()) out << " [" << b.unit << "]";
      if (!b.text) out << ", " << (b.integer ? "whole number in " : "in ") << b.range.text();
      out << "\n" << b.key << " = ";
      if (b.text) out << toml::value<std::string>(*b.text(copy));
      else if (b.integer) out << *b.integer(copy);
      else out << shortest_exact(*b.real(copy));
      out << "\n";
    }
  }
  return out.str();
}

std::string config_to_markdown(const Configuration& config) {
  Configuration copy = config;
  std::ostringstream out;
  std::string section;
  for (const ParameterBinding& b : parameter_bindings()) {
    if (b.section != section) {
      section = b.section;
      out << "\n## [" << section << "]\n\n| key | default | range | unit | meaning |\n|---|---|---|---|---|\n";
    }
    out << "| `" << b.key << "` | ";
    if (b.text) out << '"' << *b.text(copy) << '"';
    else if (b.integer) out << *b.integer(copy);
    else out << *b.real(copy);
    out << " | " << (b.text ? "" : b.range.text()) << " | " << b.unit << " | " << b.description << " |\n";
  }
  return out.str();
}

}  // namespace bellows
