// The manifest (manifest.json) to and from JSON. Reading checks everything: the format and schema
// version, every field's type and range, the configuration's constraints, the iteration numbering
// and the resume state; any fault is an InputError that names the manifest and the JSON path.
#pragma once

#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "engine/configuration.hpp"
#include "sessions/json_reader.hpp"
#include "sessions/session.hpp"

namespace bellows {

nlohmann::ordered_json manifest_to_json(const SessionManifest& manifest);
/// Two-space indented JSON text with a final newline.
std::string format_manifest(const SessionManifest& manifest);
/// `source` prefixes every error, e.g. "session /data/s1: manifest.json".
SessionManifest parse_manifest(std::string_view text, const std::string& source);

/// Every `[section] key` of the configuration, as {"section": {"key": value}}.
nlohmann::ordered_json configuration_to_json(const Configuration& config);
/// Keys not given keep their defaults (as in a TOML file); unknown keys and invalid values throw.
Configuration configuration_from_json(const JsonReader& reader);

nlohmann::ordered_json controller_state_to_json(const ControlCore::State& state);
/// Checks the ranges the configuration implies (filter length, ticks per sample).
ControlCore::State controller_state_from_json(const JsonReader& reader, const Configuration& config);

}  // namespace bellows
