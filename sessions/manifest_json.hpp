// The manifest (manifest.json) to and from JSON. Reading checks everything: the format and schema
// version, every field's type and range, the configuration's constraints, the iteration numbering
// and the resume state; any fault is an InputError that names the manifest and the JSON path.
#pragma once

#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "engine/config/configuration.hpp"
#include "sessions/json_reader.hpp"
#include "sessions/session.hpp"

namespace bellows {

nlohmann::ordered_json manifest_to_json(const SessionManifest& manifest);
/// Two-space indented JSON text with a final newline.
std::string format_manifest(const SessionManifest& manifest);

/// The text of a manifest's append-only lists (iterations, events) as far as one writer has
/// serialized them. A session's manifest is rewritten after every iteration: with the cache each
/// write serializes only what was added (not a document of every iteration, whose thousands of
/// small blocks, freed again, fragmented a lab day's heap).
struct ManifestTextCache {
  std::size_t iterations = 0;  // entries in iterations_text (all but the newest, which may change)
  std::size_t events = 0;
  std::string iterations_text;  // the entries as format_manifest writes them, ",\n"-joined
  std::string events_text;
};
/// The same text as format_manifest(manifest), reusing and extending `cache`. Entries before the
/// newest must not have changed since the cache took them (a writer only appends); a list that
/// shrank starts the cache afresh.
std::string format_manifest(const SessionManifest& manifest, ManifestTextCache& cache);
/// Throws InputError unless `text` is a bellows session's manifest by its identity alone: JSON
/// with "format": "bellows-session", an integer "schema_version" and a "program_version" (the
/// rest may be damaged). What `sessions rm` requires before removing anything.
void check_session_identity(std::string_view text, const std::string& source);
/// `source` prefixes every error, e.g. "session /data/s1: manifest.json".
SessionManifest parse_manifest(std::string_view text, const std::string& source);

/// Every `[section] key` of the configuration, as {"section": {"key": value}}.
nlohmann::ordered_json configuration_to_json(const Configuration& config);
/// Keys not given keep their defaults (as in a TOML file); unknown keys and invalid values throw.
Configuration configuration_from_json(const JsonReader& reader);

nlohmann::ordered_json controller_state_to_json(const ControlCore::State& state);
/// One joint: joint 1's fields and "tick_in_sample" (every schema version). J > 1: "tick_in_sample"
/// and "joints", one object per joint (schema version 2); version 1 kept joint 1's fields and
/// joints 2..J under another key, still read (manifest_json.cpp). Checks the ranges the
/// configuration implies (filter length, ticks per sample) and that every joint is there.
ControlCore::State controller_state_from_json(const JsonReader& reader, const Configuration& config, int joints = 1);

}  // namespace bellows
