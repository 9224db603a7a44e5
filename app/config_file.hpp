// Loading a Configuration from TOML. Every key must be known, of the right type and valid;
// anything else is an InputError naming the file, the key and what is wrong.
#pragma once

#include <cstddef>
#include <string>

#include "engine/config/configuration.hpp"

namespace bellows {

/// The largest configuration file read (a lab's is a few kilobytes).
inline constexpr std::size_t kMaxConfigFileBytes = 256 * 1024;

/// Applies the TOML text on top of `config` (keys not given keep their values).
void apply_config_toml(const std::string& toml_text, const std::string& source_name, Configuration& config);
/// Reads a TOML file on top of the defaults.
Configuration load_config_file(const std::string& path);
/// The configuration as TOML, every key with its value: a starting point for a lab's own file.
std::string config_to_toml(const Configuration& config);
/// Every key as Markdown tables, one per section (the reference part of docs/configuration.md).
std::string config_to_markdown(const Configuration& config);

}  // namespace bellows
