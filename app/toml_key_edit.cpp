#include "app/toml_key_edit.hpp"

#include <cstdio>
#include <sstream>

#include "engine/base/printable_text.hpp"

namespace bellows {
namespace {

// "[name]" or "[name]  # comment": the header of table `name` (not an array of tables, not a dotted
// sub-table).
bool is_header_of(const std::string& trimmed, const std::string& table) {
  const std::string header = "[" + table + "]";
  if (trimmed.rfind(header, 0) != 0) return false;
  const std::string_view rest = trim(std::string_view(trimmed).substr(header.size()));
  return rest.empty() || rest.front() == '#';
}

}  // namespace

bool has_table_header(const std::string& text, const std::string& table) {
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    if (is_header_of(std::string(trim(line)), table)) return true;
  }
  return false;
}

std::string toml_number(double value) {
  char text[64];
  std::snprintf(text, sizeof text, "%.9g", value);
  std::string s = text;
  // TOML wants a float to look like one when it must be read back as a float ("1" is an integer).
  if (s.find_first_of(".eEn") == std::string::npos) s += ".0";
  return s;
}

std::string with_table_values(const std::string& text, const std::string& table,
                              const std::vector<std::pair<std::string, std::string>>& values,
                              const std::string& comment) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  const auto line_for = [&](const std::pair<std::string, std::string>& kv) {
    return kv.first + " = " + kv.second + "  # " + comment;
  };

  std::vector<bool> written(values.size(), false);
  bool inside = table.empty();              // the top level comes first
  long insert_at = table.empty() ? 0 : -1;  // where missing keys go
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const std::string t(trim(lines[i]));
    if (!t.empty() && t.front() == '[') {
      if (table.empty() && inside) insert_at = static_cast<long>(i);  // the top level ends here
      inside = !table.empty() && is_header_of(t, table);
      if (inside) insert_at = static_cast<long>(i) + 1;
      continue;
    }
    if (table.empty() && inside && !t.empty() && t.front() != '#') insert_at = static_cast<long>(i) + 1;
    if (!inside) continue;
    const auto equals = t.find('=');
    if (equals == std::string::npos || t.front() == '#') continue;
    const std::string key(trim(std::string_view(t).substr(0, equals)));
    for (std::size_t v = 0; v < values.size(); ++v) {
      if (key == values[v].first) {
        lines[i] = line_for(values[v]);
        written[v] = true;
      }
    }
  }
  std::vector<std::string> missing;
  for (std::size_t v = 0; v < values.size(); ++v) {
    if (!written[v]) missing.push_back(line_for(values[v]));
  }
  if (insert_at < 0) {  // no such table yet: a new one at the end
    if (!lines.empty() && !trim(lines.back()).empty()) lines.emplace_back();
    lines.push_back("[" + table + "]");
    lines.insert(lines.end(), missing.begin(), missing.end());
  } else {
    lines.insert(lines.begin() + insert_at, missing.begin(), missing.end());
  }
  std::string out;
  for (const std::string& line : lines) out += line + "\n";
  return out;
}

}  // namespace bellows
