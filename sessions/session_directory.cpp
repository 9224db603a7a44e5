#include "sessions/session_directory.hpp"

#include <fcntl.h>
#include <linux/fs.h>  // RENAME_NOREPLACE
#include <stdio.h>     // renameat2
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <exception>
#include <stdexcept>
#include <thread>

#include "engine/base/errors.hpp"
#include "engine/base/printable_text.hpp"
#include "sessions/black_box_file.hpp"
#include "sessions/file_access.hpp"
#include "sessions/file_digest.hpp"
#include "sessions/iteration_files.hpp"
#include "sessions/manifest_json.hpp"
#include "sessions/record_columns.hpp"
#include "sessions/session_layout.hpp"

namespace bellows {
namespace fs = std::filesystem;

std::string describe_session(const fs::path& directory) { return "session " + printable(directory.string()); }

namespace {

/// A column for people: "angle_deg" -> "angle", "u_pid_bar_j2" -> "joint 2 u_pid".
std::string column_label(std::string name) {
  std::string joint;
  if (const std::size_t suffix = name.rfind("_j");
      suffix != std::string::npos && suffix + 2 < name.size() &&
      name.find_first_not_of("0123456789", suffix + 2) == std::string::npos) {
    joint = "joint " + name.substr(suffix + 2) + " ";
    name.resize(suffix);
  }
  for (const std::string unit : {"_deg", "_bar", "_s"}) {
    if (name.size() > unit.size() && name.compare(name.size() - unit.size(), unit.size(), unit) == 0) {
      name.resize(name.size() - unit.size());
      break;
    }
  }
  return joint + name;
}

/// Refuses a value a CSV file cannot hold (a NaN): before anything is written.
void check_finite(const std::vector<Eigen::VectorXd>& columns, const std::vector<std::string>& names, int index) {
  for (std::size_t c = 0; c < columns.size(); ++c) {
    for (Eigen::Index k = 0; k < columns[c].size(); ++k) {
      if (!std::isfinite(columns[c](k))) {
        throw InputError("iteration " + std::to_string(index) + ": " + column_label(names[c]) + " at index " +
                         std::to_string(k) + " is not a finite number; it cannot be saved");
      }
    }
  }
}

/// `contents` written as `relative` (a layout name) in `folder`; returns its digest.
std::string write_layout_file(const DirectoryHandle& folder, const std::string& relative, const std::string& contents,
                              DirectorySync directory_sync) {
  write_file_atomic_at(folder, session_layout::folder_and_name(relative).second, contents, directory_sync);
  return sha256_hex(contents);
}

/// Writes many iterations' files with two workers, so that one formats while the other waits for
/// the disk: a whole paper session saves in about half the time of a single thread.
void write_all_iteration_files(const DirectoryHandle& folder, const std::vector<IterationData>& iterations,
                               std::vector<IterationEntry>& entries) {
  constexpr std::size_t kWorkers = 2;
  std::atomic<std::size_t> next{0};
  std::array<std::exception_ptr, kWorkers> errors{};
  const auto work = [&](std::size_t worker) {
    try {
      for (std::size_t i = next++; i < iterations.size(); i = next++) {
        const IterationDigests digests = write_iteration_files(folder, static_cast<int>(i), iterations[i].record,
                                                               iterations[i].next_corrections_bar());
        entries[i].samples_sha256 = digests.samples_sha256;
        entries[i].telemetry_sha256 = digests.telemetry_sha256;
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

/// Renames `from` to `to` in `parent` unless `to` exists (whatever it is: a link, an empty directory).

}  // namespace

std::string write_black_box_file(const DirectoryHandle& session, int index, const std::vector<TickRecord>& ticks) {
  const DirectoryHandle faults = session.make_subdirectory(session_layout::kFaults);
  return write_layout_file(faults, session_layout::black_box_file(index), format_black_box_csv(ticks),
                           DirectorySync::kNow);
}

IterationDigests write_iteration_files(const DirectoryHandle& iterations, int index, const TrialRecord& record,
                                       const Eigen::MatrixXd& next_corrections_bar) {
  const std::vector<std::string> samples_names = samples_header(record.joint_count());
  const std::vector<std::string> telemetry_names = telemetry_header(record.joint_count());
  const std::vector<Eigen::VectorXd> samples = samples_file_values(record, next_corrections_bar);
  const std::vector<Eigen::VectorXd> telemetry = telemetry_file_values(record);
  check_finite(samples, samples_names, index);
  check_finite(telemetry, telemetry_names, index);
  IterationDigests digests;
  digests.samples_sha256 = write_layout_file(iterations, session_layout::samples_file(index),
                                             format_samples_csv(record, next_corrections_bar), DirectorySync::kLater);
  digests.telemetry_sha256 = write_layout_file(iterations, session_layout::telemetry_file(index),
                                               format_telemetry_csv(record), DirectorySync::kLater);
  return digests;
}

void write_manifest(const DirectoryHandle& session, SessionManifest& manifest, ManifestTextCache* cache) {
  manifest.updated_utc = utc_now();
  write_file_atomic_at(session, session_layout::kManifest,
                       cache ? format_manifest(manifest, *cache) : format_manifest(manifest));
}

CreatedSession create_session_directory(const fs::path& directory, const SessionManifest& manifest,
                                        const Trajectory& trajectory, const std::vector<IterationData>& iterations,
                                        const std::string& purpose,
                                        const std::vector<std::vector<TickRecord>>& black_boxes) {
  if (iterations.size() != manifest.iterations.size()) {
    throw std::invalid_argument("create_session_directory: the manifest lists a different number of iterations");
  }
  if (trajectory.joints() != manifest.joints) {
    throw std::invalid_argument("create_session_directory: the manifest's joints are not the trajectory's");
  }
  if (black_boxes.size() != manifest.black_boxes.size()) {
    throw std::invalid_argument("create_session_directory: the manifest lists a different number of black boxes");
  }
  const fs::path parent_path = directory.parent_path().empty() ? fs::path(".") : directory.parent_path();
  const std::string name = directory.filename().string();
  std::error_code error;
  // The folders a new data directory needs: each one's entry is flushed in its parent once made, or a
  // crash could lose the folder, and with it the session about to be committed inside it.
  std::vector<fs::path> missing;
  for (fs::path folder = fs::absolute(parent_path, error); !error && !folder.empty() && !fs::exists(folder, error);
       folder = folder.parent_path()) {
    missing.push_back(folder);
  }
  fs::create_directories(parent_path, error);
  if (error) throw_file_error("cannot create the data directory " + printable(parent_path.string()), error.value());
  for (auto folder = missing.rbegin(); folder != missing.rend(); ++folder) {
    sync(DirectoryHandle::open(folder->parent_path()));
  }
  const DirectoryHandle parent = DirectoryHandle::open(parent_path);
  const auto refuse_existing = [&] {
    if (const auto holder = SessionLock::holder(directory)) {
      throw SessionExistsError(describe_session(directory) + " is in use by " + *holder +
                               "; two processes never write the same session");
    }
    throw SessionExistsError(describe_session(directory) + " exists already; continue it with --resume " +
                             printable(directory.string()) + " or choose another --name");
  };
  struct stat existing {};
  if (::fstatat(parent.fd(), name.c_str(), &existing, AT_SYMLINK_NOFOLLOW) == 0) refuse_existing();

  std::string building_name = ".";  // by appends: GCC 12 warns falsely (-Wrestrict) on "." + string
  // Unique to this process and this creation: threads of one process may create sessions at once.
  static std::atomic<unsigned> creations{0};
  building_name.append(name)
      .append(".creating-")
      .append(std::to_string(::getpid()))
      .append("-")
      .append(std::to_string(creations.fetch_add(1)));
  fs::remove_all(parent_path / building_name, error);  // a leftover of this pid (a link is removed, not followed)
  if (::mkdirat(parent.fd(), building_name.c_str(), 0755) != 0) {
    throw_file_error("cannot create " + printable(directory.string()), errno);  // the session asked for
  }
  try {
    std::optional<DirectoryHandle> building = parent.subdirectory(building_name);
    if (!building)
      throw InputError("cannot create " + printable((parent_path / building_name).string()) + ": it vanished");
    SessionLock lock(*building, purpose);
    SessionManifest written = manifest;
    const DirectoryHandle iterations_folder = building->make_subdirectory(session_layout::kIterations);
    written.trajectory_sha256 = write_layout_file(*building, session_layout::kTrajectory,
                                                  format_trajectory_csv(trajectory), DirectorySync::kLater);
    write_all_iteration_files(iterations_folder, iterations, written.iterations);
    sync(iterations_folder);
    for (std::size_t i = 0; i < black_boxes.size(); ++i) {
      written.black_boxes[i].sha256 = write_black_box_file(*building, static_cast<int>(i), black_boxes[i]);
    }
    write_manifest(*building, written);
    if (const int rename_error = rename_no_replace(parent, building_name, parent, name); rename_error != 0) {
      if (rename_error == EEXIST || rename_error == ENOTEMPTY) refuse_existing();
      throw_file_error("cannot create " + printable(directory.string()), rename_error);
    }
    sync(parent);
    return {std::move(*building).moved_to(directory), std::move(lock), std::move(written)};
  } catch (...) {
    fs::remove_all(parent_path / building_name, error);
    throw;
  }
}

}  // namespace bellows
