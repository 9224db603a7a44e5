#include "app/sessions_command.hpp"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <optional>
#include <cstdio>
#include <iostream>
#include <istream>
#include <numbers>
#include <ostream>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "engine/rt/engine_state.hpp"
#include "engine/base/errors.hpp"
#include "engine/base/iteration_numbering.hpp"
#include "engine/base/printable_text.hpp"
#include "engine/control/safety.hpp"
#include "sessions/atomic_file.hpp"
#include "sessions/file_access.hpp"
#include "sessions/manifest_json.hpp"
#include "sessions/session_event_record.hpp"
#include "sessions/session_export.hpp"
#include "sessions/session_layout.hpp"
#include "sessions/session_lock.hpp"
#include "sessions/session_removal.hpp"
#include "sessions/session_store.hpp"

namespace bellows {
namespace fs = std::filesystem;
namespace {

using Json = nlohmann::ordered_json;

fs::path data_dir_of(const SessionsOptions& options) { return given_data_dir(options.data_dir); }

fs::path session_dir_of(const SessionsOptions& options) {
  if (!options.data_dir.empty()) return resolve_session_dir(options.session, given_data_dir(options.data_dir));
  fs::path data_dir;
  try {
    data_dir = data_dir_of(options);
  } catch (const InputError&) {
    // Then only a path can name the session; resolve_session_dir() says so if it is not one.
  }
  return resolve_session_dir(options.session, data_dir);
}

std::string format(const char* pattern, double value) {
  char text[64];
  std::snprintf(text, sizeof text, pattern, value);
  return text;
}

/// Text from a session's files as a terminal may show it (escaped, shortened).
std::string shown(const std::string& text) { return printable(text); }

/// JSON on stdout: every non-ASCII character as \uXXXX, so no control sequence reaches a terminal
/// (C0 controls are escaped by JSON itself, C1 and bidirectional controls are not); invalid UTF-8
/// replaced.
std::string json_text(const Json& json) { return json.dump(-1, ' ', true, nlohmann::json::error_handler_t::replace); }

/// "2024-05-01T12:03:07.123Z" -> "2024-05-01 12:03:07"
std::string short_time(const std::string& utc) {
  std::string out = printable(utc.substr(0, 19));
  if (out.size() > 10 && out[10] == 'T') out[10] = ' ';
  return out;
}

/// What the digests in the manifest say about the files just loaded (a mismatch never loads).
std::string integrity_line(const SessionIntegrity& integrity) {
  const std::string verified = std::to_string(integrity.verified_files);
  if (integrity.unverified_files == 0) return "verified: the " + verified + " files match their SHA-256 digests";
  return "unverified: " + std::to_string(integrity.unverified_files) +
         " files have no digest (saved by a bellows that kept none); " + verified + " match theirs";
}

Json summary_json(const IterationEntry& entry) {
  const IterationSummary& s = entry.summary;
  return {{"iteration", s.iteration},
          {"rms_deg", s.rms_deg},
          {"max_abs_error_deg", s.max_abs_error_deg},
          {"max_abs_correction_bar", s.max_abs_correction_bar},
          {"saturated_samples", s.saturated_samples},
          {"completed_utc", entry.completed_utc}};
}

Json listing_json(const fs::path& directory, const SessionManifest& m) {
  const double best = best_rms_deg(m);
  return {{"name", m.name},
          {"directory", directory.string()},
          {"started_utc", m.started_utc},
          {"device", m.device},
          {"trajectory", m.trajectory_name},
          {"iterations", m.iterations.size()},  // a count: iterations 0..last (docs/iterations.md)
          {"last_iteration", m.iterations.empty() ? Json(nullptr) : Json(m.iterations.size() - 1)},
          {"best_rms_deg", best < 0.0 ? Json(nullptr) : Json(best)}};
}

}  // namespace

int sessions_list_command(const SessionsOptions& options, std::ostream& out, std::ostream& err) {
  const fs::path data_dir = data_dir_of(options);
  std::vector<SessionListing> listings = list_sessions(data_dir);
  std::reverse(listings.begin(), listings.end());  // newest first, as the console's browser
  for (const SessionListing& listing : listings) {
    if (!listing.error.empty()) err << "bellows: warning: " << printable(listing.error, kPrintableLine) << std::endl;
  }
  if (options.json) {
    Json all = Json::array();
    for (const SessionListing& listing : listings) {
      all.push_back(listing.error.empty() ? listing_json(listing.directory, listing.manifest)
                                          : Json{{"name", listing.directory.filename().string()},
                                                 {"directory", listing.directory.string()},
                                                 {"error", listing.error}});
    }
    out << json_text(all) << std::endl;
    return 0;
  }
  if (listings.empty()) {
    out << "no sessions in " << shown(data_dir.string()) << std::endl;
    return 0;
  }
  char line[512];
  std::snprintf(line, sizeof line, "%-40s  %-19s  %-6s  %-16s  %10s  %12s", "NAME", "STARTED (UTC)", "DEVICE",
                "TRAJECTORY", "ITERATIONS", "BEST RMS");
  out << line << "\n";
  for (const SessionListing& listing : listings) {
    const std::string name = shown(listing.directory.filename().string());
    if (!listing.error.empty()) {
      std::snprintf(line, sizeof line, "%-40s  (unreadable: see the warning above)", name.c_str());
    } else {
      const SessionManifest& m = listing.manifest;
      const double best = best_rms_deg(m);
      std::snprintf(line, sizeof line, "%-40s  %-19s  %-6s  %-16s  %10s  %12s", name.c_str(),
                    short_time(m.started_utc).c_str(), shown(m.device).c_str(), shown(m.trajectory_name).c_str(),
                    iteration_range(static_cast<long long>(m.iterations.size())).c_str(),
                    best < 0.0 ? "-" : format("%.3f deg", best).c_str());
    }
    out << line << "\n";
  }
  out << std::flush;
  return 0;
}

namespace {

// A black box's last ticks, up to and including the fault tick: what the guard saw.
void print_black_box(std::ostream& out, int index, const BlackBoxEntry& entry, const std::vector<TickRecord>& ticks,
                     double tick_s) {
  constexpr std::size_t kShown = 5;
  out << "  " << index << ": " << shown(entry.fault) << " during iteration " << entry.iteration << ", saved "
      << short_time(entry.time_utc) << "; " << entry.ticks << " ticks (" << format("%.2f", entry.ticks * tick_s)
      << " s) in " << session_layout::black_box_file(index) << "\n";
  char line[200];
  std::snprintf(line, sizeof line, "    %9s  %-8s %9s %9s %8s %8s %8s  %s", "TIME [s]", "STATE", "ANGLE", "SET POINT",
                "P_A", "P_B", "SUPPLY", "INLET/OUTLET DUTY A, B");
  out << line << "\n";
  for (std::size_t i = ticks.size() > kShown ? ticks.size() - kShown : 0; i < ticks.size(); ++i) {
    const TickRecord& t = ticks[i];
    std::snprintf(line, sizeof line, "    %9.3f  %-8s %9.2f %9.2f %8.3f %8.3f %8.3f  %.2f/%.2f, %.2f/%.2f%s", t.time_s,
                  to_string(t.state), t.reading.joint[0].angle_rad * 180.0 / std::numbers::pi,
                  t.joint(0).desired_rad * 180.0 / std::numbers::pi, t.reading.joint[0].chamber_bar[0],
                  t.reading.joint[0].chamber_bar[1], t.reading.supply_bar, t.valves.joint[0].inlet_duty[0],
                  t.valves.joint[0].outlet_duty[0], t.valves.joint[0].inlet_duty[1], t.valves.joint[0].outlet_duty[1],
                  t.fault != FaultCode::kNone ? (std::string("  <- ") + fault_name(t.fault)).c_str() : "");
    out << line << "\n";
  }
}

}  // namespace

int sessions_show_command(const SessionsOptions& options, std::ostream& out) {
  const Session session = load_session(session_dir_of(options));  // checks every file
  if (const std::string dropped = dropped_line(session); !dropped.empty())
    std::cerr << "bellows: " << dropped << std::endl;
  const SessionManifest& m = session.manifest;
  const Configuration& c = m.configuration;
  const double best = best_rms_deg(m);
  if (options.json) {
    Json iterations = Json::array();
    for (const IterationEntry& entry : m.iterations) iterations.push_back(summary_json(entry));
    Json events = Json::array();
    for (const SessionEvent& e : m.events) events.push_back(event_to_json(e));
    Json black_boxes = Json::array();
    for (std::size_t i = 0; i < m.black_boxes.size(); ++i) {
      const BlackBoxEntry& b = m.black_boxes[i];
      black_boxes.push_back({{"fault", b.fault},
                             {"iteration", b.iteration},
                             {"time_utc", b.time_utc},
                             {"ticks", b.ticks},
                             {"file", session_layout::black_box_file(static_cast<int>(i))}});
    }
    const Json report = {{"name", m.name},
                         {"integrity",
                          {{"verified_files", session.integrity.verified_files},
                           {"unverified_files", session.integrity.unverified_files}}},
                         {"directory", session.directory.string()},
                         {"schema_version", m.schema_version},
                         {"program_version", m.program_version},
                         {"device", m.device},
                         {"device_info", m.device_info},
                         {"started_utc", m.started_utc},
                         {"updated_utc", m.updated_utc},
                         {"trajectory",
                          {{"name", m.trajectory_name},
                           {"joints", m.joints},
                           {"learning_samples", m.trajectory_samples},
                           {"sample_time_s", c.timing.sample_s()}}},
                         {"model",
                          {{"kappa_rad_per_bar", c.model.kappa_rad_per_bar},
                           {"omega0_rad_per_s", c.model.omega0_rad_per_s},
                           {"damping", c.model.damping},
                           {"source", m.model_source.empty() ? Json(nullptr) : Json(m.model_source)}}},
                         {"learning", configuration_to_json(c).at("ilc")},
                         {"best_rms_deg", best < 0.0 ? Json(nullptr) : Json(best)},
                         {"iterations", iterations},
                         {"events", events},
                         {"black_boxes", black_boxes}};
    out << json_text(report) << std::endl;
    return 0;
  }
  out << "session      " << shown(session.directory.string()) << "\n"
      << "name         " << shown(m.name) << "\n"
      << "written by   bellows " << shown(m.program_version) << " (session schema " << m.schema_version << ")\n"
      << "device       " << shown(m.device) << " " << shown(json_text(m.device_info)) << "\n"
      << "started      " << shown(m.started_utc) << "\n"
      << "updated      " << shown(m.updated_utc) << "\n"
      << "integrity    " << integrity_line(session.integrity) << "\n"
      << "trajectory   " << shown(m.trajectory_name) << ": "
      << (m.joints > 1 ? std::to_string(m.joints) + " joints, " : std::string()) << m.trajectory_samples
      << " samples every " << c.timing.sample_s() << " s (" << m.trajectory_samples * c.timing.sample_s() << " s)\n"
      << "model        kappa " << format("%g", c.model.kappa_rad_per_bar) << " rad/bar, omega0 "
      << format("%g", c.model.omega0_rad_per_s) << " 1/s, damping " << format("%g", c.model.damping)
      << (m.model_source.empty() ? std::string() : " (from the " + shown(m.model_source) + ")") << "\n"
      << "learning     " << shown(c.ilc.law) << ", m = " << c.ilc.m << ", s = " << c.ilc.s << ", w = " << c.ilc.w
      << "\n"
      << "iterations   " << iteration_range(static_cast<long long>(m.iterations.size()));
  if (best >= 0.0) out << ", best RMS " << format("%.3f", best) << " deg";
  out << "\n\n";
  char line[256];
  std::snprintf(line, sizeof line, "%9s  %9s  %15s  %20s  %9s  %s", "ITERATION", "RMS [deg]", "MAX ERROR [deg]",
                "MAX CORRECTION [bar]", "SATURATED", "COMPLETED (UTC)");
  out << line << "\n";
  for (const IterationEntry& entry : m.iterations) {
    const IterationSummary& s = entry.summary;
    std::snprintf(line, sizeof line, "%9d  %9.3f  %15.3f  %20.4f  %9d  %s", s.iteration, s.rms_deg, s.max_abs_error_deg,
                  s.max_abs_correction_bar, s.saturated_samples, short_time(entry.completed_utc).c_str());
    out << line << "\n";
  }
  if (!m.events.empty()) out << "\nevents\n";
  for (const SessionEvent& e : m.events) {
    // A console-log event holds several log lines, "HH:MM:SS source: text": one row each, indented.
    const std::string head =
        "  " + short_time(e.time_utc) + "  iteration " + std::to_string(e.iteration) + "  " + shown(e.kind) + ": ";
    // Bounded: an edited manifest's message of a million lines must not flood the terminal.
    constexpr int kMostLinesPerEvent = 100;
    std::istringstream lines(e.message);
    std::string text;
    int shown_lines = 0, skipped_lines = 0;
    while (std::getline(lines, text)) {
      if (text.empty()) continue;
      if (shown_lines == kMostLinesPerEvent) {
        ++skipped_lines;
        continue;
      }
      out << (shown_lines == 0 ? head : std::string(head.size(), ' ')) << printable(text, kPrintableLine) << "\n";
      ++shown_lines;
    }
    if (shown_lines == 0) out << head << "\n";
    if (skipped_lines > 0) out << std::string(head.size(), ' ') << "... (" << skipped_lines << " more lines)\n";
  }
  if (!m.black_boxes.empty()) out << "\nblack boxes (the last ticks before each fault; every tick in the file)\n";
  for (std::size_t i = 0; i < m.black_boxes.size(); ++i) {
    print_black_box(out, static_cast<int>(i), m.black_boxes[i], session.black_boxes[i], c.timing.tick_s);
  }
  out << std::flush;
  return 0;
}

int sessions_export_command(const SessionsOptions& options, std::ostream& out) {
  if (options.format != "csv" && options.format != "mat") {
    throw InputError("--format must be csv or mat, not '" + options.format + "'");
  }
  if (!options.mat_version.empty() && options.format != "mat") {
    throw InputError("--mat-version applies to --format mat only");
  }
  if (!options.mat_version.empty() && options.mat_version != "5" && options.mat_version != "7.3") {
    throw InputError("--mat-version must be 5 or 7.3, not '" + options.mat_version + "'");
  }
  const Session session = load_session(session_dir_of(options));
  const fs::path output = options.output.empty()
                              ? fs::path(session.directory.filename().string() + "." + options.format)
                              : fs::path(options.output);
  const MatVersion version = options.mat_version == "7.3" ? MatVersion::kV73 : MatVersion::kV5;
  const std::vector<fs::path> files =
      options.format == "csv" ? export_session_csv(session, output, options.force)
                              : std::vector<fs::path>{export_session_mat(session, output, version, options.force)};
  if (options.json) {
    Json paths = Json::array();
    for (const fs::path& file : files) paths.push_back(file.string());
    out << Json{{"format", options.format}, {"iterations", session.iterations.size()}, {"files", paths}}.dump()
        << std::endl;
    return 0;
  }
  for (const fs::path& file : files) out << "wrote " << file.string() << "\n";
  out << std::flush;
  return 0;
}

namespace {

/// The session named by `options`, checked to be a bellows session (its manifest loads, or at
/// least is there when it is damaged), so that rm never removes a directory that is not one.
fs::path existing_session(const SessionsOptions& options) {
  fs::path directory = session_dir_of(options);  // not const: returned, so moved
  std::error_code error;
  if (!fs::is_regular_file(directory / session_layout::kManifest, error)) {
    throw InputError(directory.string() + " is not a bellows session (no " + session_layout::kManifest + ")");
  }
  return directory;
}

}  // namespace

int sessions_rm_command(const SessionsOptions& options, std::istream& in, std::ostream& out, std::ostream& err) {
  const fs::path directory = session_dir_of(options);
  const std::string shown_directory = printable(directory.string());
  const auto refuse = [&](const std::string& why) {
    throw InputError("will not remove " + shown_directory + ": " + why + "; nothing was removed");
  };
  std::error_code error;
  if (fs::symlink_status(directory, error).type() == fs::file_type::symlink) {
    refuse("it is a symbolic link (remove the link itself, or name the session it points to)");
  }
  const DirectoryHandle session = open_session_directory(directory);
  // A bellows session by its manifest (a regular file, not a link, whose identity parses), and
  // holding nothing but what the session layout names.
  std::optional<std::string> manifest_text;
  try {
    manifest_text = read_regular_file_at(session, session_layout::kManifest, session_layout::kMostManifestBytes);
  } catch (const InputError& e) {
    refuse(std::string("it is not a bellows session: ") + e.what());
  }
  if (!manifest_text) refuse(std::string("it is not a bellows session (no ") + session_layout::kManifest + ")");
  try {
    check_session_identity(*manifest_text, session_layout::kManifest);
  } catch (const InputError& e) {
    refuse(std::string("it is not a bellows session: ") + e.what());
  }
  if (const std::vector<std::string> foreign = foreign_session_entries(session); !foreign.empty()) {
    std::string names;
    for (std::size_t i = 0; i < foreign.size() && i < 5; ++i) names += (i ? ", " : "") + printable(foreign[i]);
    if (foreign.size() > 5) names += ", ...";
    refuse("it holds what is not a bellows session's (" + names + ")");
  }
  std::string description = "session " + shown_directory;
  try {
    const SessionManifest m = parse_manifest(*manifest_text, session_layout::kManifest);
    description += " (iterations " + iteration_range(static_cast<long long>(m.iterations.size())) + ", started " +
                   short_time(m.started_utc) + ")";
  } catch (const InputError&) {
    description += " (damaged)";
  }
  // Asking creates nothing: the holder is read without creating a lock file; the lock is taken
  // only to remove.
  if (const auto holder = SessionLock::holder(session)) refuse("it is in use by " + *holder);
  if (!options.yes) {
    err << "remove " << description << "? [y/N] " << std::flush;
    std::string answer;
    std::getline(in, answer);
    if (answer != "y" && answer != "Y" && answer != "yes") {
      err << "bellows: not removed" << (in ? "" : " (no answer; --yes removes without asking)") << std::endl;
      return 1;
    }
  }
  const SessionLock lock(session, "bellows sessions rm");  // not while a run or a console writes it
  // Out of sight first (hidden names are not sessions), so a removal cut short leaves no half session.
  std::string hidden_name = ".";
  hidden_name += directory.filename().string();
  hidden_name += ".removing-" + std::to_string(::getpid());
  const fs::path parent = directory.parent_path().empty() ? fs::path(".") : directory.parent_path();
  const fs::path hidden = parent / hidden_name;
  fs::rename(directory, hidden, error);
  if (error) throw_file_error("cannot remove " + shown_directory, error.value());
  remove_session_entries(session);  // through the directory's own descriptor: it moved with it
  if (::rmdir(hidden.c_str()) != 0) {
    throw InputError("cannot remove " + printable(hidden.string()) + " (renamed from " + shown_directory +
                     "): " + std::strerror(errno));
  }
  sync_directory(parent);
  if (options.json) {
    out << Json{{"removed", directory.string()}}.dump() << std::endl;
  } else {
    out << "removed " << directory.string() << std::endl;
  }
  return 0;
}

int sessions_rename_command(const SessionsOptions& options, std::ostream& out) {
  validate_session_name(options.new_name);
  const fs::path directory = existing_session(options);
  const fs::path target = rename_session(directory, options.new_name);
  if (options.json) {
    out << Json{{"renamed", directory.string()}, {"directory", target.string()}}.dump() << std::endl;
  } else {
    out << "renamed " << directory.string() << " to " << target.string() << std::endl;
  }
  return 0;
}

}  // namespace bellows
