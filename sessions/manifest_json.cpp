#include "sessions/manifest_json.hpp"

#include <algorithm>
#include <charconv>
#include <set>

#include "engine/model/arm_model.hpp"
#include "engine/config/configuration_cost.hpp"
#include "engine/config/learning_law_factory.hpp"
#include "engine/base/errors.hpp"
#include "sessions/file_digest.hpp"
#include "sessions/session_event_record.hpp"
#include "sessions/session_layout.hpp"

namespace bellows {
namespace {

constexpr const char* kFormat = "bellows-session";
constexpr int kMostIterations = 1000000;
constexpr int kMostSamples = 100000000;

using Json = nlohmann::ordered_json;

template <typename Derived>
Json vector_to_json(const Eigen::DenseBase<Derived>& values) {
  Json out = Json::array();
  for (Eigen::Index i = 0; i < values.size(); ++i) out.push_back(values(i));
  return out;
}

Json pressure_state_to_json(const PressureController::State& s) {
  Json history = Json::array();
  for (double value : s.history_bar) history.push_back(value);
  return {{"history_bar", history}, {"count", s.count}, {"next", s.next}, {"sum_bar", s.sum_bar}};
}

PressureController::State pressure_state_from_json(const JsonReader& r, int filter_samples) {
  PressureController::State s;
  const JsonReader history = r["history_bar"];
  if (history.size() != s.history_bar.size()) {
    history.fail("expected " + std::to_string(s.history_bar.size()) + " numbers, found " +
                 std::to_string(history.size()));
  }
  for (std::size_t i = 0; i < s.history_bar.size(); ++i) s.history_bar[i] = history[i].number();
  s.count = r["count"].integer(0, filter_samples);
  s.next = r["next"].integer(0, filter_samples - 1);
  s.sum_bar = r["sum_bar"].number();
  return s;
}

/// A file's digest: optional (sessions saved before digests have none), else 64 hex digits.
std::string digest_from_json(const JsonReader& r, const char* key) {
  if (!r.has(key)) return "";
  std::string digest = r[key].text();  // not const: returned by move
  if (!is_sha256_hex(digest)) r[key].fail("expected a SHA-256 digest: 64 lowercase hex digits");
  return digest;
}

/// Adds `"key": digest` unless the digest is unknown.
void put_digest(Json& object, const char* key, const std::string& digest) {
  if (!digest.empty()) object[key] = digest;
}

/// `"learned_with": {"law": ..., <its weight keys>: ...}`: what learned the iteration's correction.
Json learned_with_to_json(const LearnedWith& learned) {
  Json out = {{"law", learned.law}};
  for (const auto& [key, value] : learned.weights) out[key] = value;
  return out;
}

LearnedWith learned_with_from_json(const JsonReader& r) {
  r.expect_object();
  LearnedWith out;
  out.law = r["law"].text();
  const std::vector<std::string> laws = learning_law_names();
  if (std::find(laws.begin(), laws.end(), out.law) == laws.end())
    r["law"].fail("unknown learning law '" + out.law + "'");
  const std::vector<std::string> keys = learning_law_weight_keys(out.law);
  for (const auto& item : r.json().items()) {
    if (item.key() != "law" && std::find(keys.begin(), keys.end(), item.key()) == keys.end()) {
      r[item.key()].fail("law " + out.law + " has no weight '" + item.key() + "'");
    }
  }
  for (const std::string& key : keys) {
    const double value = r[key].number();
    try {
      check_parameter_value(*find_parameter("ilc", key), value);
    } catch (const InputError& error) {
      r[key].fail(error.what());
    }
    out.weights.emplace_back(key, value);
  }
  return out;
}

Json summary_to_json(const IterationEntry& entry) {
  const IterationSummary& s = entry.summary;
  Json out = {{"iteration", s.iteration},
              {"completed_utc", entry.completed_utc},
              {"rms_deg", s.rms_deg},
              {"max_abs_error_deg", s.max_abs_error_deg},
              {"max_abs_correction_bar", s.max_abs_correction_bar},
              {"saturated_samples", s.saturated_samples},
              {"samples_file", session_layout::samples_file(s.iteration, entry.samples_revision)},
              {"telemetry_file", session_layout::telemetry_file(s.iteration)}};
  put_digest(out, "samples_sha256", entry.samples_sha256);
  put_digest(out, "telemetry_sha256", entry.telemetry_sha256);
  if (s.learned_with.known())
    out["learned_with"] = learned_with_to_json(s.learned_with);  // absent: not learned or not recorded
  return out;
}

double non_negative(const JsonReader& r) {
  const double value = r.number();
  if (value < 0.0) r.fail("must not be negative");
  return value;
}

/// Which revision of iteration `index`'s samples file the manifest names: only the layout's own
/// names ("iterations/iteration_0004.csv", "iterations/iteration_0004.r2.csv") are accepted.
int samples_revision_from_json(const JsonReader& r, int index) {
  const std::string text = r.text();
  const std::string plain = session_layout::samples_file(index);
  if (text == plain) return 0;
  const std::string stem = plain.substr(0, plain.size() - 4) + ".r";
  if (text.size() > stem.size() + 4 && text.compare(0, stem.size(), stem) == 0 &&
      text.compare(text.size() - 4, 4, ".csv") == 0) {
    const std::string digits = text.substr(stem.size(), text.size() - stem.size() - 4);
    int revision = 0;
    const auto [end, error] = std::from_chars(digits.data(), digits.data() + digits.size(), revision);
    if (error == std::errc() && end == digits.data() + digits.size() && revision >= 1 &&
        revision <= session_layout::kMostSamplesRevisions && session_layout::samples_file(index, revision) == text) {
      return revision;
    }
  }
  r.fail("expected \"" + plain + "\" (or a revision of it, \"" + session_layout::samples_file(index, 1) + "\")");
}

IterationEntry summary_from_json(const JsonReader& r, int index, int samples) {
  IterationEntry entry;
  IterationSummary& s = entry.summary;
  s.iteration = r["iteration"].integer(0, kMostIterations);
  if (s.iteration != index) {
    r["iteration"].fail("iterations must be numbered 0, 1, 2, ...: expected " + std::to_string(index) + ", found " +
                        std::to_string(s.iteration));
  }
  entry.completed_utc = r["completed_utc"].text();
  s.rms_deg = non_negative(r["rms_deg"]);
  s.max_abs_error_deg = non_negative(r["max_abs_error_deg"]);
  s.max_abs_correction_bar = non_negative(r["max_abs_correction_bar"]);
  s.saturated_samples = r["saturated_samples"].integer(0, samples);
  entry.samples_revision = samples_revision_from_json(r["samples_file"], index);
  if (const std::string expected = session_layout::telemetry_file(index); r["telemetry_file"].text() != expected) {
    r["telemetry_file"].fail("expected \"" + expected + "\"");
  }
  entry.samples_sha256 = digest_from_json(r, "samples_sha256");
  entry.telemetry_sha256 = digest_from_json(r, "telemetry_sha256");
  if (r.has("learned_with")) s.learned_with = learned_with_from_json(r["learned_with"]);
  return entry;
}

Json black_box_to_json(const BlackBoxEntry& b, int index) {
  Json out = {{"time_utc", b.time_utc},
              {"iteration", b.iteration},
              {"fault", b.fault},
              {"ticks", b.ticks},
              {"file", session_layout::black_box_file(index)}};
  put_digest(out, "sha256", b.sha256);
  return out;
}

BlackBoxEntry black_box_from_json(const JsonReader& r) {
  constexpr int kMostTicks = 100000000;
  return {r["time_utc"].text(), r["iteration"].integer(0, kMostIterations), r["fault"].text(),
          r["ticks"].integer(1, kMostTicks), digest_from_json(r, "sha256")};
}

}  // namespace

Json configuration_to_json(const Configuration& config) {
  Configuration copy = config;  // the bindings hand out pointers into a mutable configuration
  Json out = Json::object();
  for (const ParameterBinding& b : parameter_bindings()) {
    Json& section = out[b.section];
    if (b.text) section[b.key] = *b.text(copy);
    else if (b.integer) section[b.key] = *b.integer(copy);
    else section[b.key] = *b.real(copy);
  }
  return out;
}

Configuration configuration_from_json(const JsonReader& reader) {
  reader.expect_object();
  const auto& bindings = parameter_bindings();
  std::set<std::string> sections;
  for (const ParameterBinding& b : bindings) sections.insert(b.section);
  Configuration config;
  for (const auto& [section, values] : reader.json().items()) {
    if (!sections.count(section)) reader.fail("unknown section \"" + section + "\" (written by a newer bellows?)");
    const JsonReader section_reader = reader[section];
    section_reader.expect_object();
    for (const auto& item : values.items()) {
      const std::string& key = item.key();
      const ParameterBinding* binding = nullptr;
      for (const ParameterBinding& b : bindings) {
        if (b.section == section && b.key == key) binding = &b;
      }
      if (binding == nullptr) section_reader.fail("unknown key \"" + key + "\" (written by a newer bellows?)");
      const JsonReader value = section_reader[key];
      if (binding->text) *binding->text(config) = value.text();
      else if (binding->integer) *binding->integer(config) = value.integer(-1000000000, 1000000000);
      else *binding->real(config) = value.number();
    }
  }
  try {
    validate_configuration(config);
  } catch (const InputError& error) {
    reader.fail(error.what());
  }
  config.controller.gas = config.plant.gas;  // as the TOML loader does: one ambient for both
  return config;
}

namespace {

/// The key of "resume.controller" under which J-joint sessions of schema version 1 (the J-joint
/// format of 410db9c, Nov 30, up to schema version 2) kept joints 2..J's controllers, one object
/// each, beside joint 1's fields. Read, never written: version 2 keeps every joint's in kJointsKey.
constexpr const char* kVersion1OtherJointsKey = "more_joints";
/// Every joint's controllers, one object each, joint 1 first (schema version 2, J > 1).
constexpr const char* kJointsKey = "joints";

/// One joint's controllers: joint 1's fields of "controller" (as every session saved them), and
/// each entry of kJointsKey (or of kVersion1OtherJointsKey).
Json joint_state_to_json(const ControlCore::JointState& s) {
  return {
      {"pid",
       {{"integral_s", s.pid.integral_s},
        {"previous_output", s.pid.previous_output},
        {"has_previous", s.pid.has_previous}}},
      {"pressure_a", pressure_state_to_json(s.pressure_a)},
      {"pressure_b", pressure_state_to_json(s.pressure_b)},
      {"setpoints",
       {{"a_bar", s.setpoints.a_bar}, {"b_bar", s.setpoints.b_bar}, {"saturation_sign", s.setpoints.saturation_sign}}},
      {"hold_rad", s.hold_rad},
      {"desired_rad", s.desired_rad},
      {"u_total_bar", s.u_total_bar}};
}

void joint_state_from_json(const JsonReader& r, const Configuration& config, ControlCore::JointState& s) {
  const JsonReader pid = r["pid"];
  s.pid.integral_s = pid["integral_s"].number();
  s.pid.previous_output = pid["previous_output"].number();
  s.pid.has_previous = pid["has_previous"].boolean();
  s.pressure_a = pressure_state_from_json(r["pressure_a"], config.controller.filter_samples);
  s.pressure_b = pressure_state_from_json(r["pressure_b"], config.controller.filter_samples);
  const JsonReader setpoints = r["setpoints"];
  s.setpoints.a_bar = setpoints["a_bar"].number();
  s.setpoints.b_bar = setpoints["b_bar"].number();
  s.setpoints.saturation_sign = setpoints["saturation_sign"].integer(-1, 1);
  s.hold_rad = r["hold_rad"].number();
  s.desired_rad = r["desired_rad"].number();
  s.u_total_bar = r["u_total_bar"].number();
}

}  // namespace

Json controller_state_to_json(const ControlCore::State& s) {
  if (s.joint_count > 1) {
    Json out = {{"tick_in_sample", s.tick_in_sample}, {kJointsKey, Json::array()}};
    for (int joint = 0; joint < s.joint_count; ++joint) {
      out[kJointsKey].push_back(joint_state_to_json(s.joints[static_cast<std::size_t>(joint)]));
    }
    return out;
  }
  // One joint: its fields and the tick, exactly as every session saved them.
  Json out = joint_state_to_json(s.joints[0]);
  out["tick_in_sample"] = s.tick_in_sample;
  return out;
}

ControlCore::State controller_state_from_json(const JsonReader& r, const Configuration& config, int joints) {
  ControlCore::State s;
  s.tick_in_sample = r["tick_in_sample"].integer(0, config.timing.ticks_per_sample - 1);
  s.joint_count = joints;
  if (r.has(kJointsKey) || (joints > 1 && !r.has(kVersion1OtherJointsKey))) {
    const JsonReader all = r[kJointsKey];
    if (all.size() != static_cast<std::size_t>(joints)) {
      all.fail("expected " + std::to_string(joints) + " entries (one per joint of the session's " +
               std::to_string(joints) + "), found " + std::to_string(all.size()));
    }
    for (int joint = 0; joint < joints; ++joint) {
      joint_state_from_json(all[static_cast<std::size_t>(joint)], config, s.joints[static_cast<std::size_t>(joint)]);
    }
    return s;
  }
  joint_state_from_json(r, config, s.joints[0]);
  if (joints > 1 || r.has(kVersion1OtherJointsKey)) {
    const JsonReader others = r[kVersion1OtherJointsKey];
    if (others.size() != static_cast<std::size_t>(joints - 1)) {
      others.fail("expected " + std::to_string(joints - 1) + " entries (joints 2 to " + std::to_string(joints) +
                  " of the session's " + std::to_string(joints) + "), found " + std::to_string(others.size()));
    }
    for (int joint = 1; joint < joints; ++joint) {
      joint_state_from_json(others[static_cast<std::size_t>(joint - 1)], config,
                            s.joints[static_cast<std::size_t>(joint)]);
    }
  }
  return s;
}

namespace {

/// The manifest without its iterations and events (both empty lists).
Json manifest_head_to_json(const SessionManifest& m);

}  // namespace

Json manifest_to_json(const SessionManifest& m) {
  Json out = manifest_head_to_json(m);
  Json& iterations = out["iterations"];
  for (const IterationEntry& entry : m.iterations) iterations.push_back(summary_to_json(entry));
  Json& events = out["events"];
  for (const SessionEvent& event : m.events) events.push_back(event_to_json(event));
  return out;
}

namespace {

Json manifest_head_to_json(const SessionManifest& m) {
  const Configuration& c = m.configuration;
  const double sample_s = c.timing.sample_s();
  const DiscreteArmModel model = discretize_arm_model(c.model, sample_s);
  const Json configuration = configuration_to_json(c);
  Json black_boxes = Json::array();
  for (std::size_t i = 0; i < m.black_boxes.size(); ++i) {
    black_boxes.push_back(black_box_to_json(m.black_boxes[i], static_cast<int>(i)));
  }
  Json trajectory = {{"name", m.trajectory_name},
                     {"file", session_layout::kTrajectory},
                     {"learning_samples", m.trajectory_samples},
                     {"sample_time_s", sample_s},
                     {"duration_s", m.trajectory_samples * sample_s}};
  put_digest(trajectory, "sha256", m.trajectory_sha256);
  if (m.joints > 1) trajectory["joints"] = m.joints;  // absent: one joint (and the files as they always were)
  Json out = {
      {"format", kFormat},
      {"schema_version", session_schema_version_for(m.joints)},  // what is written here, whatever was read
      {"program_version", m.program_version},
      {"name", m.name},
      {"device", m.device},
      {"device_info", m.device_info},
      {"started_utc", m.started_utc},
      {"updated_utc", m.updated_utc},
      {"trajectory", trajectory},
      // Derived from the configuration, written for readers; ignored when loading.
      {"model",
       {{"kappa_rad_per_bar", c.model.kappa_rad_per_bar},
        {"omega0_rad_per_s", c.model.omega0_rad_per_s},
        {"damping", c.model.damping},
        {"sample_time_s", sample_s},
        {"A", {vector_to_json(model.A.row(0)), vector_to_json(model.A.row(1))}},
        {"B", vector_to_json(model.B)},
        {"C", vector_to_json(model.C)}}},
      {"learning", configuration.at("ilc")},  // the law and its weights, as [ilc] has them
      {"configuration", configuration},
      {"iterations", Json::array()},
      {"events", Json::array()},
      {"black_boxes", black_boxes},
  };
  if (!m.model_source.empty())
    out["model"]["source"] = m.model_source;  // absent: not recorded (a rig check learns nothing)
  if (!m.first_correction.is_null()) out["first_correction"] = m.first_correction;
  if (m.resume) {
    Json resume = {{"next_iteration", static_cast<int>(m.iterations.size())}};
    // A first-format state (no clock ticks) is written back as it was read: without "exact",
    // which says the clock's ticks are recorded. The next completed iteration replaces it.
    const bool first_format = m.resume->exact() && !m.resume->clock_ticks;
    if (!first_format) resume["exact"] = m.resume->exact();
    if (m.resume->exact()) {
      if (m.resume->clock_ticks) resume["clock_ticks"] = *m.resume->clock_ticks;
      resume["controller"] = controller_state_to_json(*m.resume->controller);
      resume["device"] = m.resume->device;
    }
    out["resume"] = std::move(resume);
  }
  return out;
}

std::string dump_manifest_json(const Json& json) {
  return json.dump(2, ' ', false, nlohmann::json::error_handler_t::replace);
}

/// Appends `element` to `list` as an element of a top-level list in the file: four spaces deeper
/// than its own dump (no JSON string holds a raw newline, so every newline starts a line).
void append_list_element(std::string& list, const Json& element) {
  if (!list.empty()) list += ",\n";
  list += "    ";
  for (const char c : dump_manifest_json(element)) {
    list += c;
    if (c == '\n') list += "    ";
  }
}

/// Replaces the empty top-level list `key` of `text` by the elements `head` and then `tail`.
void splice_list(std::string& text, const char* key, const std::string& head, const std::string& tail) {
  if (head.empty() && tail.empty()) return;
  const std::string empty = std::string("\n  \"") + key + "\": []";  // top level: two spaces, after a newline
  const std::size_t at = text.find(empty);
  if (at == std::string::npos) throw std::logic_error(std::string("format_manifest: no top-level list ") + key);
  std::string filled = std::string("\n  \"") + key + "\": [\n" + head;
  if (!head.empty() && !tail.empty()) filled += ",\n";
  filled += tail;
  filled += "\n  ]";
  text.replace(at, empty.size(), filled);
}

/// Brings `text` (`count` entries) up to `keep` entries of `entries`.
template <typename Entry, typename ToJson>
void extend_cache(const std::vector<Entry>& entries, std::size_t keep, std::size_t& count, std::string& text,
                  ToJson to_json) {
  if (count > keep) {  // the list shrank (another manifest): start afresh
    count = 0;
    text.clear();
  }
  for (; count < keep; ++count) append_list_element(text, to_json(entries[count]));
}

}  // namespace

std::string format_manifest(const SessionManifest& manifest) {
  ManifestTextCache fresh;
  return format_manifest(manifest, fresh);
}

std::string format_manifest(const SessionManifest& m, ManifestTextCache& cache) {
  const std::size_t iterations_kept = m.iterations.empty() ? 0 : m.iterations.size() - 1;
  extend_cache(m.iterations, iterations_kept, cache.iterations, cache.iterations_text, summary_to_json);
  const std::size_t events_kept = m.events.empty() ? 0 : m.events.size() - 1;
  extend_cache(m.events, events_kept, cache.events, cache.events_text, event_to_json);
  std::string newest_iteration, newest_event;
  if (!m.iterations.empty()) append_list_element(newest_iteration, summary_to_json(m.iterations.back()));
  if (!m.events.empty()) append_list_element(newest_event, event_to_json(m.events.back()));
  std::string text = dump_manifest_json(manifest_head_to_json(m));
  splice_list(text, "iterations", cache.iterations_text, newest_iteration);
  splice_list(text, "events", cache.events_text, newest_event);
  return text + "\n";
}

void check_session_identity(std::string_view text, const std::string& source) {
  const Json json = parse_json(text, source);
  const JsonReader r(json, source);
  if (!json.is_object() || !json.contains("format") || json["format"] != kFormat) {
    r.fail("not a bellows session manifest (expected \"format\": \"" + std::string(kFormat) + "\")");
  }
  r["schema_version"].integer(0, 1000000);
  r["program_version"].text();
}

SessionManifest parse_manifest(std::string_view text, const std::string& source) {
  const Json json = parse_json(text, source);
  const JsonReader r(json, source);
  if (!json.is_object() || !json.contains("format") || json["format"] != kFormat) {
    r.fail("not a bellows session manifest (expected \"format\": \"" + std::string(kFormat) + "\")");
  }
  SessionManifest m;
  m.schema_version = r["schema_version"].integer(0, 1000000);
  if (m.schema_version < kOldestSessionSchemaVersion || m.schema_version > kSessionSchemaVersion) {
    const std::string oldest = kOldestSessionSchemaVersion < kSessionSchemaVersion
                                   ? "s " + std::to_string(kOldestSessionSchemaVersion) + " to"
                                   : "";
    r["schema_version"].fail("schema version " + std::to_string(m.schema_version) +
                             " is not supported (this bellows reads version" + oldest + " " +
                             std::to_string(kSessionSchemaVersion) + ")" +
                             (m.schema_version > kSessionSchemaVersion ? ": a newer bellows wrote it" : ""));
  }
  m.program_version = r["program_version"].text();
  m.name = r["name"].text();
  m.device = r["device"].text();
  r["device_info"].expect_object();
  m.device_info = r["device_info"].json();
  m.started_utc = r["started_utc"].text();
  m.updated_utc = r["updated_utc"].text();
  m.configuration = configuration_from_json(r["configuration"]);
  if (r.has("model") && r["model"].has("source"))
    m.model_source = r["model"]["source"].text();  // the values: the configuration's
  const JsonReader trajectory = r["trajectory"];
  m.trajectory_name = trajectory["name"].text();
  m.trajectory_samples =
      trajectory["learning_samples"].integer(m.configuration.trajectory.min_learning_samples, kMostSamples);
  try {  // the ticks and the law's matrices such a trial implies, before anything reads or allocates them
    check_trial_cost(m.configuration, m.trajectory_samples);
  } catch (const InputError& error) {
    trajectory["learning_samples"].fail(error.what());
  }
  m.trajectory_sha256 = digest_from_json(trajectory, "sha256");
  if (trajectory.has("joints")) m.joints = trajectory["joints"].integer(1, kMaxJoints);  // absent: one joint
  const JsonReader iterations = r["iterations"];
  for (std::size_t i = 0; i < iterations.size(); ++i) {
    m.iterations.push_back(summary_from_json(iterations[i], static_cast<int>(i), m.trajectory_samples));
  }
  const JsonReader events = r["events"];
  for (std::size_t i = 0; i < events.size(); ++i) m.events.push_back(event_from_json(events[i]));
  if (r.has("black_boxes")) {  // sessions saved before black boxes were kept have none
    const JsonReader black_boxes = r["black_boxes"];
    for (std::size_t i = 0; i < black_boxes.size(); ++i) m.black_boxes.push_back(black_box_from_json(black_boxes[i]));
  }
  if (r.has("first_correction")) {  // absent: the run started with feedback only
    r["first_correction"].expect_object();
    m.first_correction = r["first_correction"].json();
  }
  if (r.has("resume")) {
    const JsonReader resume = r["resume"];
    const int next = resume["next_iteration"].integer(0, kMostIterations);
    if (next != static_cast<int>(m.iterations.size())) {
      resume["next_iteration"].fail("expected " + std::to_string(m.iterations.size()) +
                                    " (the iterations listed), found " + std::to_string(next));
    }
    ResumeState state;
    // The first format (1afa6a9, Nov 21) always saved the controllers and the device, without
    // "exact" and "clock_ticks": exact, the clock's ticks left to the device's own time.
    const bool first_format = !resume.has("exact");
    if (first_format || resume["exact"].boolean()) {
      if (!first_format || resume.has("clock_ticks")) {
        const JsonReader ticks = resume["clock_ticks"];
        if (!ticks.json().is_number_integer() || ticks.json().get<long long>() < 0)
          ticks.fail("expected a whole number >= 0");
        state.clock_ticks = ticks.json().get<long long>();
      }
      state.controller = controller_state_from_json(resume["controller"], m.configuration, m.joints);
      resume["device"].expect_object();
      state.device = resume["device"].json();
    }
    m.resume = std::move(state);
  } else if (!m.iterations.empty()) {
    r.fail("missing \"resume\": a session with completed iterations must hold the state to continue from");
  }
  return m;
}

}  // namespace bellows
