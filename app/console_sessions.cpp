#include "app/console_sessions.hpp"

#include "engine/config/learning_law_factory.hpp"
#include "app/memory_policy.hpp"

#include <any>
#include <cstdio>
#include <optional>
#include <ctime>
#include <sstream>

#include "app/transfer_sources.hpp"
#include "engine/base/errors.hpp"
#include "sessions/session_store.hpp"

namespace bellows {
namespace {

constexpr const char* kPurpose = "bellows console";
// Log entries saved after a session's creation travel as one event per save (one manifest write),
// a line per entry: "HH:MM:SS source: text".
constexpr const char* kConsoleLogKind = "console-log";

/// What of the console's log belongs in a session: not a trial's routine state changes, nor the
/// learner's lines (the iterations themselves are saved with their results).
bool worth_saving(const ui::LogEntry& e) {
  return !e.routine && (e.source != ui::LogSource::kLearner || !e.event_kind.empty());
}

std::string kind_of(const ui::LogEntry& e) {
  if (!e.event_kind.empty()) return e.event_kind;
  if (e.important && e.text.rfind("FAULT", 0) == 0) return "fault";
  return ui::to_string(e.source);
}

ui::LogSource source_of(const std::string& name) {
  if (name == "operator") return ui::LogSource::kOperator;
  if (name == "engine" || name == "fault") return ui::LogSource::kEngine;
  if (name == "learner" || name == ui::kModelRefitEvent) return ui::LogSource::kLearner;
  if (name == "device") return ui::LogSource::kDevice;
  return ui::LogSource::kSession;
}

std::string local_clock_of(const std::string& utc) {
  const std::string date = local_date_of(utc);  // "YYYY-MM-DD HH:MM"
  if (date.size() != 16 || utc.size() < 19) return utc;
  return date.substr(11) + utc.substr(16, 3);  // seconds do not depend on the time zone
}

/// The saved events as log entries; a console-log event gives back its lines.
std::vector<ui::LogEntry> log_of(const SessionManifest& m) {
  std::vector<ui::LogEntry> out;
  for (const SessionEvent& e : m.events) {
    if (e.kind == kConsoleLogKind) {
      std::istringstream lines(e.message);
      std::string line;
      while (std::getline(lines, line)) {
        // "HH:MM:SS [t=ENGINE_S ]source: text" (sessions before the engine time: without it)
        std::size_t from = 9;
        double engine_time_s = -1.0;
        if (line.compare(from, 2, "t=") == 0) {
          const auto space = line.find(' ', from);
          if (space == std::string::npos) continue;
          try {
            engine_time_s = std::stod(line.substr(from + 2, space - from - 2));
          } catch (const std::exception&) {
            engine_time_s = -1.0;
          }
          from = space + 1;
        }
        const auto colon = line.find(": ", from);
        if (line.size() < 10 || colon == std::string::npos) continue;
        const std::string source = line.substr(from, colon - from);
        out.push_back({line.substr(0, 8),
                       engine_time_s,
                       source_of(source),
                       line.substr(colon + 2),
                       source == "fault",
                       false,
                       e.time_utc,
                       e.iteration,
                       {}});
      }
      continue;
    }
    const bool known = e.kind == "operator" || e.kind == "engine" || e.kind == "session" || e.kind == "fault";
    out.push_back({local_clock_of(e.time_utc),
                   e.engine_time_s,
                   source_of(e.kind),
                   known ? e.message : e.kind + ": " + e.message,
                   e.kind == "fault",
                   false,
                   e.time_utc,
                   e.iteration,
                   {}});
  }
  return out;
}

/// The manifest's first_correction for a new session: the transfer its iteration 0 ran with, in the
/// shape `bellows run --transfer-from` records (transfer_json); null when it ran with feedback only.
nlohmann::ordered_json first_correction_json(const ui::Experiment& e) {
  if (!e.first_correction || e.trials.empty() || e.trials.front().origin.rfind("transferred", 0) != 0) return nullptr;
  TransferReport report;
  for (const ui::TransferSourceNote& note : e.first_correction->sources) {
    report.sources.push_back({note.name, note.directory, note.trajectory, note.trials, note.last_rms_deg});
  }
  report.result = e.first_correction->result;
  nlohmann::ordered_json out = nlohmann::ordered_json::parse(transfer_json(report).dump());
  out["by"] = "console";  // taken with T (run --transfer-from records no "by")
  return out;
}

/// What the console shows of a session read from disk: its configuration, device, trajectory and
/// trials (their records move out of `loaded`).
ui::SessionSnapshot snapshot_of(Session& loaded, const std::filesystem::path& directory) {
  ui::SessionSnapshot snapshot;
  snapshot.config = loaded.manifest.configuration;
  snapshot.device_name = loaded.manifest.device;
  snapshot.rig_profile = rig_profile_of(loaded.manifest);
  ui::Experiment& e = snapshot.experiment;
  e = ui::Experiment::start(std::make_shared<const Trajectory>(loaded.trajectory));
  const int n = loaded.trajectory.learning_samples();
  for (std::size_t i = 0; i < loaded.iterations.size(); ++i) {
    ui::Trial trial;
    trial.iteration = static_cast<int>(i);
    const TrialRecord& record = loaded.iterations[i].record;
    trial.correction_bar.resize(n, record.joint_count());
    for (int j = 0; j < record.joint_count(); ++j)
      trial.correction_bar.col(j) = record.joint_samples(j).u_ilc_bar.head(n);
    trial.summary = loaded.manifest.iterations[i].summary;
    if (trial.summary.joint_rms_deg.size() != record.joint_count()) {  // each joint's RMS, from its record
      trial.summary.joint_rms_deg.resize(record.joint_count());
      for (int j = 0; j < record.joint_count(); ++j) trial.summary.joint_rms_deg(j) = record.joint_rms_error_deg(j);
    }
    trial.record = std::move(loaded.iterations[i].record);
    trial.origin = "saved";
    e.trials.push_back(std::move(trial));
  }
  e.session_location = directory.string();
  return snapshot;
}

}  // namespace

std::string local_date_of(const std::string& utc) {
  std::tm t{};
  if (std::sscanf(utc.c_str(), "%d-%d-%dT%d:%d:%d", &t.tm_year, &t.tm_mon, &t.tm_mday, &t.tm_hour, &t.tm_min,
                  &t.tm_sec) != 6) {
    return utc;
  }
  t.tm_year -= 1900;
  t.tm_mon -= 1;
  const std::time_t seconds = timegm(&t);
  std::tm local{};
  localtime_r(&seconds, &local);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%d %H:%M", &local);
  return text;
}

StoreSessionGateway::StoreSessionGateway(std::string device_name, nlohmann::ordered_json device_info,
                                         const std::string& data_dir, std::string model_source)
    : device_name_(std::move(device_name)),
      device_info_(std::move(device_info)),
      model_source_(std::move(model_source)) {
  if (!data_dir.empty()) {
    data_dir_ = data_dir;
    return;
  }
  try {
    data_dir_ = default_data_dir();
  } catch (const InputError& error) {
    reason_ = error.what();
  }
}

std::string StoreSessionGateway::save(const ui::SessionSnapshot& snapshot) {
  const std::lock_guard<std::mutex> guard(mutex_);
  const ui::Experiment& e = snapshot.experiment;
  if (!e.trajectory) throw InputError("nothing to save: no trajectory");
  // A session this gateway created whose first save then failed is continued, not created twice.
  const bool continuing =
      writer_ && (e.session_location.empty() ? unconfirmed_events_ != kConfirmed &&
                                                   writer_->manifest().trajectory_name == e.trajectory->name &&
                                                   writer_->manifest().iterations.empty()
                                             : writer_->directory() == e.session_location);
  const std::size_t saved_events = e.session_location.empty() && continuing ? unconfirmed_events_ : e.saved_events;

  // Log entries not yet in the session: the snapshot holds the newest ones of `events_total`.
  const std::size_t held = snapshot.events.size();
  const std::size_t first_held = snapshot.events_total - held;
  const std::size_t first_new = continuing ? std::max(saved_events, first_held) - first_held : 0;

  // The snapshot's trials are iterations first_trial..; the trial of iteration i is at i - first_trial.
  const auto first = static_cast<std::size_t>(snapshot.first_trial);
  const std::size_t end = first + e.trials.size();
  const auto trial_at = [&](std::size_t iteration) -> const ui::Trial& { return e.trials[iteration - first]; };
  std::size_t first_trial = 0;
  std::optional<SessionWriter::Batch> batch;  // one console save, one commit (the manifest's rename)
  if (continuing) {
    batch.emplace(*writer_);
    first_trial = writer_->manifest().iterations.size();
    if (first_trial > end) throw InputError("the session on disk has more iterations than the console");
    if (first_trial < first)
      throw std::logic_error("StoreSessionGateway::save: unsaved iterations missing from the snapshot");
    if (e.settings_changed) writer_->set_configuration(snapshot.config);
    std::string lines;
    for (std::size_t i = first_new; i < held; ++i) {
      const ui::LogEntry& entry = snapshot.events[i];
      if (worth_saving(entry) && !entry.event_kind.empty()) {  // an event of its own, in its place
        if (!lines.empty()) writer_->record_event(kConsoleLogKind, lines);
        lines.clear();
        writer_->record_event(entry.event_kind, entry.text);
      } else if (worth_saving(entry)) {
        lines += entry.clock + " ";
        if (entry.engine_time_s >= 0.0) {
          char stamp[40];
          std::snprintf(stamp, sizeof stamp, "t=%.3f ", entry.engine_time_s);
          lines += stamp;
        }
        lines += kind_of(entry) + ": " + entry.text + "\n";
      }
    }
    if (!lines.empty()) writer_->record_event(kConsoleLogKind, lines);
    // Learned (or chosen) after the last saved trial: on disk before the next trial starts.
    if (first_trial == end && first_trial > first && e.next_unsaved) {
      writer_->update_next_correction(trial_at(end - 1).record, e.next_correction_bar);
    }
  } else {
    if (first != 0) throw std::logic_error("StoreSessionGateway::save: a new session needs every iteration");
    SessionManifest header;
    header.device = snapshot.device_name;
    header.device_info = device_info_;
    if (snapshot.device_name == "sim") header.device_info["seed"] = snapshot.seed;  // the arm it continues with
    header.configuration = snapshot.config;
    header.model_source = model_source_;
    header.first_correction = first_correction_json(e);
    for (const ui::LogEntry& entry : snapshot.events) {
      if (worth_saving(entry)) {
        header.events.push_back({entry.time_utc, entry.iteration, kind_of(entry), entry.text, entry.engine_time_s});
      }
    }
    writer_.reset();  // the previous session's lock goes first
    writer_.emplace(SessionWriter::create(data_dir_, "", std::move(header), *e.trajectory, kPurpose));
    unconfirmed_events_ = snapshot.events_total;  // in its header already
    batch.emplace(*writer_);
  }
  for (std::size_t i = first_trial; i < end; ++i) {
    const Eigen::MatrixXd& next = i + 1 < end ? trial_at(i + 1).correction_bar : e.next_correction_bar;
    // On the wall clock the controllers' state is not captured (a resume arms afresh); on --clock
    // sim the trial carries the state it ended in (app/run_recording.hpp).
    const auto* end_state = std::any_cast<ResumeState>(&trial_at(i).end_state);
    writer_->save_iteration(trial_at(i).record, trial_at(i).summary, next,
                            end_state != nullptr ? *end_state : ResumeState{});
  }
  for (std::size_t i = writer_->manifest().black_boxes.size(); i < e.faults.size(); ++i) {
    writer_->save_black_box(e.faults[i].fault, e.faults[i].ticks);
  }
  batch->commit();
  unconfirmed_events_ = kConfirmed;
  return_free_memory();  // on the saving worker: what the saved records held goes back to the system
  return writer_->directory().string();
}

std::string StoreSessionGateway::name_refusal(const std::string& location, const std::string& name) {
  // No lock: a save may hold it for a while, and this runs on the UI thread.
  const std::filesystem::path directory(location);
  if (directory.filename() == name) return {};  // its own name: nothing to do
  return session_name_refusal(name, directory.parent_path());
}

void StoreSessionGateway::read_quietly(const std::function<void()>& read) {
  const std::lock_guard<std::mutex> guard(mutex_);
  read();
}

std::string StoreSessionGateway::rename(const std::string& name) {
  const std::lock_guard<std::mutex> guard(mutex_);
  if (!writer_) throw InputError("nothing to name yet: the session is created with the first trial");
  const std::filesystem::path from = writer_->directory();
  if (from.filename() == name) return from.string();
  if (const std::string why = session_name_refusal(name, from.parent_path()); !why.empty()) throw InputError(why);
  writer_.reset();  // its lock goes with it; rename_session takes it, then the writer again below
  std::filesystem::path now = from;
  std::string failure;
  try {
    now = rename_session(from, name);  // the directory and the manifest's name, as `sessions rename`
  } catch (const std::exception& error) {
    failure = error.what();
  }
  Session loaded;
  writer_.emplace(SessionWriter::open(now, kPurpose, loaded));
  if (!failure.empty()) throw InputError(failure);
  return now.string();
}

std::vector<ui::SessionListing> StoreSessionGateway::list() {
  const std::lock_guard<std::mutex> guard(mutex_);
  std::vector<ui::SessionListing> out;
  for (const SessionListing& s : list_sessions(data_dir_)) {
    ui::SessionListing l;
    l.location = s.directory.string();
    l.name = s.directory.filename().string();
    l.error = s.error;
    if (s.error.empty()) {
      l.date = local_date_of(s.manifest.started_utc);
      l.trajectory = s.manifest.trajectory_name;
      l.iterations = static_cast<int>(s.manifest.iterations.size());
      l.best_rms_deg = best_rms_deg(s.manifest);
      l.device = s.manifest.device;
    }
    out.push_back(std::move(l));
  }
  return out;
}

ui::SessionSnapshot StoreSessionGateway::read_trials(const std::string& location) {
  std::filesystem::path directory;
  {
    const std::lock_guard<std::mutex> guard(mutex_);
    directory = resolve_session_dir(location, data_dir_);
  }
  Session loaded = load_session(directory);  // read only: no lock, our own session unchanged
  return snapshot_of(loaded, directory);
}

ui::SessionSnapshot StoreSessionGateway::open(const std::string& location) {
  const std::lock_guard<std::mutex> guard(mutex_);
  const std::filesystem::path directory = resolve_session_dir(location, data_dir_);
  if (writer_ && writer_->directory() == directory) writer_.reset();  // reopening our own session
  Session loaded;
  SessionWriter writer = SessionWriter::open(directory, kPurpose, loaded);
  const SessionManifest& m = loaded.manifest;
  if (m.device != device_name_) {
    throw InputError("session " + directory.string() + " was recorded on the device '" + m.device +
                     "'; this console drives '" + device_name_ + "' (open it with bellows console --session " +
                     directory.string() + ")");
  }
  ui::SessionSnapshot snapshot = snapshot_of(loaded, directory);
  const auto seed = m.device_info.find("seed");
  if (seed != m.device_info.end() && seed->is_number_unsigned()) snapshot.seed = seed->get<std::uint64_t>();
  ui::Experiment& e = snapshot.experiment;
  if (!loaded.iterations.empty()) {
    e.next_correction_bar = loaded.iterations.back().next_corrections_bar();
    e.next_origin = "saved with the session";
    // The correction the last trial ran with again: the next step learns first.
    e.next_tried = e.next_correction_bar.isApprox(e.trials.back().correction_bar) ||
                   (e.next_correction_bar.isZero() && e.trials.back().correction_bar.isZero());
    // Learned after the last iteration with the session's law, unless it is the one that ran again.
    e.next_learned_with = e.next_tried ? e.trials.back().summary.learned_with : learned_with(m.configuration);
  }
  for (std::size_t i = 0; i < loaded.black_boxes.size(); ++i) {
    e.faults.push_back({m.black_boxes[i].fault, m.black_boxes[i].iteration, std::move(loaded.black_boxes[i])});
  }
  e.saved_trials = static_cast<int>(e.trials.size());
  e.saved_faults = static_cast<int>(e.faults.size());
  snapshot.events = log_of(m);
  if (const std::string dropped = dropped_line(loaded); !dropped.empty()) {  // the writer removed it: say so once
    const std::string now = utc_now();
    snapshot.events.push_back({local_clock_of(now),
                               -1.0,
                               ui::LogSource::kSession,
                               dropped,
                               true,
                               false,
                               now,
                               static_cast<int>(loaded.iterations.size()),
                               {}});
  }
  snapshot.events_total = snapshot.events.size();
  writer_.reset();
  writer_.emplace(std::move(writer));
  unconfirmed_events_ = kConfirmed;
  return snapshot;
}

}  // namespace bellows
