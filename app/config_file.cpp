#include "app/config_file.hpp"

#include <fstream>
#include <set>
#include <sstream>

#include <toml++/toml.h>

#include "engine/errors.hpp"
#include "sessions/file_access.hpp"

namespace bellows {

void apply_config_toml(const std::string& toml_text, const std::string& source_name, Configuration& config) {
  toml::table root;
  try {
    root = toml::parse(toml_text, source_name);
  } catch (const toml::parse_error& error) {
    std::ostringstream where;
    where << source_name << ":" << error.source().begin.line << ":" << error.source().begin.column << ": "
          << error.description();
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
      const ParameterBinding* binding = nullptr;
      for (const ParameterBinding& b : bindings) {
        if (b.section == section && b.key == key) binding = &b;
      }
      const std::string where = "config " + source_name + ": [" + section + "] " + key;
      if (binding == nullptr) throw InputError(where + ": unknown key");
      if (binding->text) {
        if (!value.is_string()) throw InputError(where + ": expected a string");
        *binding->text(config) = *value.value<std::string>();
      } else if (binding->integer) {
        if (!value.is_integer()) throw InputError(where + ": expected a whole number");
        *binding->integer(config) = static_cast<int>(*value.value<std::int64_t>());
      } else {
        if (!value.is_number()) throw InputError(where + ": expected a number");
        *binding->real(config) = *value.value<double>();
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
  constexpr std::size_t kMostConfigBytes = std::size_t{1} << 20;
  const std::string text = read_regular_file(path, kMostConfigBytes, "config");
  Configuration config;
  apply_config_toml(text, path, config);
  return config;
}

std::string config_to_toml(const Configuration& config) {
  Configuration copy = config;
  toml::table root;
  for (const ParameterBinding& b : parameter_bindings()) {
    if (!root.contains(b.section)) root.insert(b.section, toml::table{});
    toml::table& section = *root[b.section].as_table();
    if (b.text) section.insert(b.key, *b.text(copy));
    else if (b.integer) section.insert(b.key, static_cast<std::int64_t>(*b.integer(copy)));
    else section.insert(b.key, *b.real(copy));
  }
  std::ostringstream out;
  out << root << "\n";
  return out.str();
}

std::string config_to_markdown(const Configuration& config) {
  Configuration copy = config;
  std::ostringstream out;
  std::string section;
  for (const ParameterBinding& b : parameter_bindings()) {
    if (b.section != section) {
      section = b.section;
      out << "\n## [" << section << "]\n\n| key | default | unit | meaning |\n|---|---|---|---|\n";
    }
    out << "| `" << b.key << "` | ";
    if (b.text) out << '"' << *b.text(copy) << '"';
    else if (b.integer) out << *b.integer(copy);
    else out << *b.real(copy);
    out << " | " << b.unit << " | " << b.description << " |\n";
  }
  return out.str();
}

}  // namespace bellows
