// A session in memory: what a run saves and what loading gives back. On disk it is a directory
// (docs/session-format.md): manifest.json, trajectory.csv and, per iteration, the ILC-rate samples
// and the tick-rate telemetry as CSV.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <nlohmann/json.hpp>

#include "engine/config/configuration.hpp"
#include "engine/control/control_core.hpp"
#include "engine/rt/engine_messages.hpp"
#include "engine/operator/learning_session.hpp"
#include "engine/trial/trajectory.hpp"
#include "engine/trial/trial_record.hpp"

namespace bellows {

/// The manifest layout this program writes. It reads every version from the oldest up to this one
/// (a field an older version lacks gets its documented default: docs/session-format.md,
/// "Versions"); a newer version is refused. Bump it when what is written changes in a way an older
/// reader would misread, and add a fixture of the new format (tests/fixtures/sessions/README.md).
inline constexpr int kSessionSchemaVersion = 2;
inline constexpr int kOldestSessionSchemaVersion = 1;
/// The version a session of `joints` joints is written in: 1 for one joint (its files exactly as
/// every earlier bellows wrote them), 2 for several (every joint's controllers alike in
/// resume.controller.joints; manifest_json.hpp).
constexpr int session_schema_version_for(int joints) { return joints > 1 ? 2 : 1; }

/// The program's version, written into every manifest.
std::string program_version();

/// Something that happened: the run starting or resuming, a fault, an operator's action.
struct SessionEvent {
  std::string time_utc;  // ISO 8601, e.g. 2024-05-01T12:00:00.123Z
  int iteration = 0;     // the iteration running or next to run when it happened
  std::string kind;      // "start", "resume", "finish", "fault", "configuration", "note", ...
  std::string message;
  double engine_time_s = -1.0;  // the engine's time when it happened, when known (console log lines); else negative
};

/// A fault's black box as the manifest lists it; its ticks are in session_layout::black_box_file().
struct BlackBoxEntry {
  std::string time_utc;     // when it was saved
  int iteration = 0;        // the iteration running or next to run when the fault fired
  std::string fault;        // fault_name(), e.g. "overpressure"
  int ticks = 0;            // rows in the file: the ticks before the fault and the fault tick
  std::string sha256 = {};  // the file's digest as saved; empty in sessions saved before digests
};

/// One completed iteration as the manifest lists it.
struct IterationEntry {
  IterationSummary summary;
  std::string completed_utc;
  std::string samples_sha256 = {};    // the files' digests; empty in sessions saved before digests
  std::string telemetry_sha256 = {};  // were kept
  int samples_revision = 0;           // which samples file: session_layout::samples_file(iteration, revision)
};

/// What continuing the run exactly needs beyond the correction: the controllers' state (every
/// joint's: manifest_json.hpp says how), the
/// device's own state (which only the device's owner understands, kept here as JSON) and the
/// simulated clock. Only a run on a simulated clock can be captured exactly; after a wall-clock
/// run `controller` is empty and a resume starts from freshly armed controllers.
struct ResumeState {
  std::optional<ControlCore::State> controller;
  nlohmann::ordered_json device = nlohmann::ordered_json::object();
  // The simulated clock's ticks. Unknown (empty) in sessions of the first format (Nov 21, before
  // the simulated clock was recorded): the resume takes them from the device's own time.
  std::optional<long long> clock_ticks;
  bool exact() const { return controller.has_value(); }
};

struct SessionManifest {
  int schema_version = session_schema_version_for(1);
  std::string program_version;
  std::string name;
  std::string device;  // Device::name(), e.g. "sim"
  // The arm's joints J: every iteration file holds J joints' columns, the trajectory J columns.
  // Written only when J > 1 (a one-joint manifest is what it always was); absent: one joint.
  int joints = 1;
  nlohmann::ordered_json device_info = nlohmann::ordered_json::object();  // e.g. {"seed": 1}
  std::string started_utc;
  std::string updated_utc;
  Configuration configuration;
  // Where the configuration's [model] (the model the learning used) came from: "configuration", or
  // "rig_profile" (the identified model of the rig profile device_info names); empty in sessions
  // saved before it was recorded.
  std::string model_source;
  std::string trajectory_name;
  int trajectory_samples = 0;     // N learning samples (the file holds N + 1)
  std::string trajectory_sha256;  // empty in sessions saved before digests were kept
  std::vector<IterationEntry> iterations;
  std::vector<SessionEvent> events;
  std::vector<BlackBoxEntry> black_boxes;  // numbered 0, 1, ... in the order the faults fired
  std::optional<ResumeState> resume;       // present once an iteration has completed
  // Where the first trial's correction came from when it was not zero (a learning transfer: its
  // sources, method and prediction); null for a run that started with feedback only.
  nlohmann::ordered_json first_correction;
};

/// One iteration's signals: the trial record and the correction learned from it for the next trial.
/// Column j of the correction is joint j + 1's, as TrialRecord::joints[j] is its record.
struct IterationData {
  TrialRecord record;
  Eigen::MatrixXd next_corrections = {};  // N x J

  int joints() const { return record.joint_count(); }
  /// Every joint's correction, N x J (one column per joint): what a J-joint learning takes.
  const Eigen::MatrixXd& next_corrections_bar() const { return next_corrections; }
  /// Sets every joint's correction from N x J.
  void set_next_corrections(const Eigen::MatrixXd& corrections_bar) { next_corrections = corrections_bar; }
};

/// How many of a loaded session's files the manifest's digests vouch for. A file whose digest does
/// not match is refused while loading; a file without a digest (saved by an older bellows) is
/// loaded and counted as unverified.
struct SessionIntegrity {
  int verified_files = 0;
  int unverified_files = 0;
};

struct Session {
  std::filesystem::path directory;
  SessionIntegrity integrity;
  /// Not empty when a save was interrupted (a crash, a full disk): what it had written but not
  /// committed, which is not part of the session, in one line ("iteration 5; the correction
  /// learned from iteration 4"). The session loaded is its last committed state.
  std::string dropped;
  SessionManifest manifest;
  Trajectory trajectory;
  std::vector<IterationData> iterations;             // in the order of manifest.iterations
  std::vector<std::vector<TickRecord>> black_boxes;  // in the order of manifest.black_boxes, oldest tick first
};

/// The rig profile's name the session was recorded with (device_info "rig_profile"); "" without one.
std::string rig_profile_of(const SessionManifest& manifest);

/// Current UTC time in the manifest's format.
std::string utc_now();

}  // namespace bellows
