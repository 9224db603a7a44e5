#include "sessions/session_store.hpp"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <exception>
#include <thread>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <tuple>

#include "engine/errors.hpp"
#include "sessions/atomic_file.hpp"
#include "sessions/black_box_file.hpp"
#include "sessions/iteration_files.hpp"
#include "sessions/manifest_json.hpp"
#include "sessions/session_directory.hpp"
#include "sessions/session_layout.hpp"

namespace bellows {
namespace fs = std::filesystem;
namespace {

std::string describe(const fs::path& directory) { return "session " + directory.string(); }

std::string read_session_file(const fs::path& directory, const std::string& relative) {
  const fs::path path = directory / relative;
  std::error_code error;
  if (!fs::exists(path, error)) throw InputError(describe(directory) + ": " + relative + " is missing");
  try {
    return read_file(path);
  } catch (const InputError& read_error) {
    throw InputError(describe(directory) + ": " + relative + ": " + read_error.what());
  }
}

void check_finite(const Eigen::VectorXd& values, int index, const char* what) {
  for (Eigen::Index k = 0; k < values.size(); ++k) {
    if (!std::isfinite(values(k))) {
      throw InputError("iteration " + std::to_string(index) + ": " + what + " at index " + std::to_string(k) +
                       " is not a finite number; it cannot be saved");
    }
  }
}

void check_record(const TrialRecord& record, const Eigen::VectorXd& next_correction_bar, int index) {
  const TrialSamples& s = record.samples;
  for (const auto& [values, what] :
       {std::pair{&s.time_s, "time"}, {&s.setpoint_rad, "angle set point"}, {&s.angle_rad, "angle"},
        {&s.error_rad, "error"}, {&s.u_pid_bar, "u_pid"}, {&s.u_ilc_bar, "u_ilc"}, {&s.u_total_bar, "u_tot"},
        {&s.pressure_a_bar, "pressure A"}, {&s.pressure_b_bar, "pressure B"}, {&s.setpoint_a_bar, "pressure A set point"},
        {&s.setpoint_b_bar, "pressure B set point"}, {&next_correction_bar, "next correction"}}) {
    check_finite(*values, index, what);
  }
  const TrialTicks& t = record.ticks;
  for (const Eigen::VectorXd* values : {&t.time_s, &t.angle_rad, &t.pressure_a_bar, &t.pressure_b_bar, &t.supply_bar,
                                        &t.setpoint_a_bar, &t.setpoint_b_bar, &t.inlet_a, &t.outlet_a, &t.inlet_b,
                                        &t.outlet_b}) {
    check_finite(*values, index, "telemetry");
  }
}

}  // namespace

fs::path default_data_dir() {
  // XDG Base Directory: relative values are invalid and must be ignored.
  const char* xdg = std::getenv("XDG_DATA_HOME");
  if (xdg != nullptr && xdg[0] == '/') return fs::path(xdg) / "bellows" / "sessions";
  const char* home = std::getenv("HOME");
  if (home != nullptr && home[0] == '/') return fs::path(home) / ".local" / "share" / "bellows" / "sessions";
  throw InputError("no data directory: neither XDG_DATA_HOME nor HOME is an absolute path; pass --data-dir");
}

std::string default_session_name(std::time_t start, const std::string& trajectory_name) {
  std::tm local{};
  ::localtime_r(&start, &local);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "%Y-%m-%d_%H-%M-%S", &local);
  std::string safe;
  for (char c : trajectory_name) {
    const bool plain = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' || c == '_';
    safe += plain ? c : '-';
  }
  return std::string(stamp) + "_" + (safe.empty() ? "trajectory" : safe.substr(0, 64));
}

void validate_session_name(const std::string& name) {
  const std::string what = "session name '" + name + "'";
  if (name.empty()) throw InputError("the session name must not be empty");
  if (name.size() > 200) throw InputError(what + " is longer than 200 characters");
  if (name.front() == '.') throw InputError(what + " must not start with '.'");
  for (char c : name) {
    if (c == '/' || static_cast<unsigned char>(c) < 0x20 || c == 0x7f) {
      throw InputError(what + " must be a plain directory name (no '/', no control characters)");
    }
  }
}

fs::path resolve_session_dir(const std::string& path_or_name, const fs::path& data_dir) {
  std::error_code error;
  if (path_or_name.empty()) throw InputError("no session given");
  std::string path = path_or_name;
  while (path.size() > 1 && path.back() == '/') path.pop_back();  // "s1/" names s1, whose filename() is then "s1"
  if (fs::is_directory(path, error)) return fs::path(path);
  if (path.find('/') == std::string::npos && !data_dir.empty() && fs::is_directory(data_dir / path, error)) {
    return data_dir / path;
  }
  throw InputError("session " + path_or_name + ": no such directory" +
                   (data_dir.empty() ? std::string() : " (nor a session of that name in " + data_dir.string() + ")"));
}

SessionManifest load_manifest(const fs::path& directory) {
  std::error_code error;
  if (!fs::is_directory(directory, error)) throw InputError(describe(directory) + ": no such directory");
  const std::string text = read_session_file(directory, session_layout::kManifest);
  return parse_manifest(text, describe(directory) + ": " + session_layout::kManifest);
}

Session load_session(const fs::path& directory) {
  Session session;
  session.directory = directory;
  session.manifest = load_manifest(directory);
  const SessionManifest& m = session.manifest;
  const Configuration& config = m.configuration;
  const int samples = m.trajectory_samples;
  session.trajectory = parse_trajectory_csv_file(read_session_file(directory, session_layout::kTrajectory),
                                                 describe(directory) + ": " + session_layout::kTrajectory,
                                                 m.trajectory_name, samples, config.timing.sample_s(), config.trajectory);
  session.iterations.resize(m.iterations.size());
  for (std::size_t i = 0; i < m.iterations.size(); ++i) {
    const int index = static_cast<int>(i);
    IterationData& data = session.iterations[i];
    const std::string samples_file = session_layout::samples_file(index);
    const std::string telemetry_file = session_layout::telemetry_file(index);
    parse_samples_csv(read_session_file(directory, samples_file), describe(directory) + ": " + samples_file, samples,
                      config.timing.sample_s(), data);
    parse_telemetry_csv(read_session_file(directory, telemetry_file), describe(directory) + ": " + telemetry_file,
                        samples, config.timing.ticks_per_sample, config.timing.tick_s, data);
    // The files and the manifest must tell the same story.
    const double rms = data.record.rms_error_deg();
    const double listed = m.iterations[i].summary.rms_deg;
    if (std::abs(rms - listed) > 1e-9 * std::max(1.0, listed)) {
      throw InputError(describe(directory) + ": " + samples_file + ": its RMS error " + std::to_string(rms) +
                       " deg differs from the manifest's " + std::to_string(listed) + " deg");
    }
  }
  for (std::size_t i = 0; i < m.black_boxes.size(); ++i) {
    const std::string file = session_layout::black_box_file(static_cast<int>(i));
    session.black_boxes.push_back(
        parse_black_box_csv(read_session_file(directory, file), describe(directory) + ": " + file, m.black_boxes[i].ticks));
  }
  return session;
}

void write_black_box_file(const fs::path& directory, int index, const std::vector<TickRecord>& ticks) {
  const fs::path faults = directory / session_layout::kFaults;
  std::error_code error;
  const bool created = fs::create_directories(faults, error);
  if (error) throw InputError("cannot create " + faults.string() + ": " + error.message());
  if (created) sync_directory(directory);  // the new directory's entry is durable too
  write_file_atomic(directory / session_layout::black_box_file(index), format_black_box_csv(ticks), DirectorySync::kNow);
}

void write_iteration_files(const fs::path& directory, int index, const TrialRecord& record,
                           const Eigen::VectorXd& next_correction_bar) {
  check_record(record, next_correction_bar, index);
  write_file_atomic(directory / session_layout::samples_file(index), format_samples_csv(record, next_correction_bar),
                    DirectorySync::kLater);
  write_file_atomic(directory / session_layout::telemetry_file(index), format_telemetry_csv(record),
                    DirectorySync::kLater);
}

void write_manifest(const fs::path& directory, SessionManifest& manifest) {
  manifest.updated_utc = utc_now();
  write_file_atomic(directory / session_layout::kManifest, format_manifest(manifest));
}

namespace {

/// Writes many iterations' files with two workers, so that one formats while the other waits for
/// the disk: a whole paper session saves in about half the time of a single thread.
void write_all_iteration_files(const fs::path& directory, const std::vector<IterationData>& iterations) {
  constexpr std::size_t kWorkers = 2;
  std::atomic<std::size_t> next{0};
  std::array<std::exception_ptr, kWorkers> errors{};
  const auto work = [&](std::size_t worker) {
    try {
      for (std::size_t i = next++; i < iterations.size(); i = next++) {
        write_iteration_files(directory, static_cast<int>(i), iterations[i].record, iterations[i].next_correction_bar);
      }
    } catch (...) {
      errors[worker] = std::current_exception();
      next = iterations.size();  // the others stop too
    }
  };
  {
    std::jthread helper(work, 1);
    work(0);
  }
  for (const std::exception_ptr& error : errors) {
    if (error) std::rethrow_exception(error);
  }
}

}  // namespace

SessionLock create_session_directory(const fs::path& directory, const SessionManifest& manifest,
                                     const Trajectory& trajectory, const std::vector<IterationData>& iterations,
                                     const std::string& purpose,
                                     const std::vector<std::vector<TickRecord>>& black_boxes) {
  if (iterations.size() != manifest.iterations.size()) {
    throw std::invalid_argument("create_session_directory: the manifest lists a different number of iterations");
  }
  if (black_boxes.size() != manifest.black_boxes.size()) {
    throw std::invalid_argument("create_session_directory: the manifest lists a different number of black boxes");
  }
  const fs::path parent = directory.parent_path().empty() ? fs::path(".") : directory.parent_path();
  std::error_code error;
  fs::create_directories(parent, error);
  if (error) throw InputError("cannot create the data directory " + parent.string() + ": " + error.message());
  const auto refuse_existing = [&] {
    if (const auto holder = SessionLock::holder(directory)) {
      throw InputError(describe(directory) + " is in use by " + *holder + "; two processes never write the same session");
    }
    throw InputError(describe(directory) + " exists already; continue it with --resume " + directory.string() +
                     " or choose another --name");
  };
  if (fs::exists(directory, error)) refuse_existing();

  std::string building_name = ".";  // by appends: GCC 12 warns falsely (-Wrestrict) on "." + string
  building_name.append(directory.filename().string()).append(".creating-").append(std::to_string(::getpid()));
  const fs::path building = parent / building_name;
  fs::remove_all(building, error);
  fs::create_directories(building / session_layout::kIterations, error);
  if (error) throw InputError("cannot create " + building.string() + ": " + error.message());
  try {
    SessionLock lock(building, purpose);
    write_file_atomic(building / session_layout::kTrajectory, format_trajectory_csv(trajectory), DirectorySync::kLater);
    write_all_iteration_files(building, iterations);
    sync_directory(building / session_layout::kIterations);
    for (std::size_t i = 0; i < black_boxes.size(); ++i) write_black_box_file(building, static_cast<int>(i), black_boxes[i]);
    SessionManifest copy = manifest;
    write_manifest(building, copy);
    if (::rename(building.c_str(), directory.c_str()) != 0) {
      const int rename_error = errno;
      if (rename_error == EEXIST || rename_error == ENOTEMPTY) refuse_existing();
      throw InputError("cannot create " + directory.string() + ": " + std::strerror(rename_error));
    }
    sync_directory(parent);
    return lock;
  } catch (...) {
    fs::remove_all(building, error);
    throw;
  }
}

void save_session(const Session& session, const fs::path& directory) {
  create_session_directory(directory, session.manifest, session.trajectory, session.iterations, "bellows save",
                           session.black_boxes);
}

std::vector<SessionListing> list_sessions(const fs::path& data_dir) {
  std::vector<SessionListing> listings;
  std::error_code error;
  if (!fs::is_directory(data_dir, error)) return listings;
  for (const auto& entry : fs::directory_iterator(data_dir, error)) {
    const std::string name = entry.path().filename().string();
    if (name.empty() || name.front() == '.' || !entry.is_directory(error)) continue;
    SessionListing listing;
    listing.directory = entry.path();
    try {
      listing.manifest = load_manifest(entry.path());
    } catch (const InputError& load_error) {
      listing.error = load_error.what();
    }
    listings.push_back(std::move(listing));
  }
  std::sort(listings.begin(), listings.end(), [](const SessionListing& a, const SessionListing& b) {
    return std::tie(a.manifest.started_utc, a.directory) < std::tie(b.manifest.started_utc, b.directory);
  });
  return listings;
}

double best_rms_deg(const SessionManifest& manifest) {
  double best = -1.0;
  for (const IterationEntry& entry : manifest.iterations) {
    if (best < 0.0 || entry.summary.rms_deg < best) best = entry.summary.rms_deg;
  }
  return best;
}

}  // namespace bellows
