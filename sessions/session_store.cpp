#include "sessions/session_store.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <exception>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <tuple>

#include "engine/base/errors.hpp"
#include "engine/base/printable_text.hpp"
#include "sessions/black_box_file.hpp"
#include "sessions/csv_table.hpp"
#include "sessions/file_access.hpp"
#include "sessions/file_digest.hpp"
#include "sessions/iteration_files.hpp"
#include "sessions/manifest_json.hpp"
#include "sessions/record_columns.hpp"
#include "sessions/session_directory.hpp"
#include "sessions/session_layout.hpp"
#include "sessions/session_lock.hpp"
#include "sessions/atomic_file.hpp"
#include "sessions/uncommitted_files.hpp"

namespace bellows {
namespace fs = std::filesystem;
namespace {

/// A loaded session's folders: `iterations` and `faults` are opened only if they exist, and are
/// refused when they are links or not directories.
struct SessionFolders {
  const DirectoryHandle& root;
  std::optional<DirectoryHandle> iterations, faults;

  const DirectoryHandle* folder(const std::string& name) const {
    if (name.empty()) return &root;
    if (name == session_layout::kIterations) return iterations ? &*iterations : nullptr;
    if (name == session_layout::kFaults) return faults ? &*faults : nullptr;
    return nullptr;
  }
};

/// The file `relative` (a layout name) of the session, at most `max_bytes`, checked against its
/// digest in the manifest when there is one.
std::string read_session_file(const SessionFolders& folders, const std::string& relative, std::size_t max_bytes,
                              const std::string& digest, SessionIntegrity& integrity) {
  const std::string where = describe_session(folders.root.path());
  const auto [folder_name, name] = session_layout::folder_and_name(relative);
  const DirectoryHandle* folder = folders.folder(folder_name);
  std::optional<std::string> text;
  try {
    if (folder != nullptr) text = read_regular_file_at(*folder, name, max_bytes);
  } catch (const InputError& error) {
    throw InputError(where + ": " + (folder_name.empty() ? "" : folder_name + "/") + error.what());
  }
  if (!text) throw InputError(where + ": " + relative + " is missing");
  if (digest.empty()) {
    ++integrity.unverified_files;
  } else if (sha256_hex(*text) != digest) {
    throw InputError(where + ": " + relative +
                     " was changed after it was saved: its SHA-256 digest differs from the one the manifest records");
  } else {
    ++integrity.verified_files;
  }
  return std::move(*text);
}

/// A folder of the session, refused when it is a link or not a directory.
std::optional<DirectoryHandle> session_folder(const DirectoryHandle& root, const char* name) {
  try {
    return root.subdirectory(name);
  } catch (const InputError& error) {
    throw InputError(describe_session(root.path()) + ": " + error.what());
  }
}

/// load_session's work: every iteration when `only` is null, else only those it lists and no black box.
Session load_session_part(const DirectoryHandle& directory, const std::vector<int>* only);

/// RMS error over every joint and learning sample (deg).
double overall_rms_deg(const TrialRecord& record) {
  double sum_of_squares = 0.0;
  for (int joint = 0; joint < record.joint_count(); ++joint) {
    const double rms = record.joint_rms_error_deg(joint);
    sum_of_squares += rms * rms;
  }
  return std::sqrt(sum_of_squares / record.joint_count());
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

fs::path given_data_dir(const std::string& option_value) {
  if (option_value.empty()) return default_data_dir();
  fs::path dir(option_value);  // not const: returned by move
  std::error_code error;
  const fs::file_status status = fs::status(dir, error);
  if (status.type() == fs::file_type::not_found)
    throw InputError("--data-dir " + printable(dir.string(), kPrintableField) + ": no such directory");
  if (error) throw_file_error("--data-dir " + printable(dir.string(), kPrintableField), error.value());
  if (status.type() != fs::file_type::directory)
    throw InputError("--data-dir " + printable(dir.string(), kPrintableField) + ": not a directory");
  return dir;
}

std::string default_session_name(std::time_t start, const std::string& trajectory_name) {
  std::tm local{};
  ::localtime_r(&start, &local);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "%Y-%m-%d_%H-%M-%S", &local);
  std::string safe;
  for (char c : trajectory_name) {
    const bool plain =
        (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' || c == '_';
    safe += plain ? c : '-';
  }
  return std::string(stamp) + "_" + (safe.empty() ? "trajectory" : safe.substr(0, 64));
}

void validate_session_name(const std::string& name) {
  const std::string what = "session name '" + printable(name) + "'";
  if (name.empty()) throw InputError("the session name must not be empty");
  if (name.size() > 200) throw InputError(what + " is longer than 200 characters");
  if (name.front() == '.') throw InputError(what + " must not start with '.'");
  // Printable UTF-8 only: a name is echoed in listings, messages and the console.
  if (name.find('/') != std::string::npos || printable(name, name.size() * 8) != name) {
    throw InputError(what + " must be a plain directory name (no '/', no control characters)");
  }
}

std::string session_name_refusal(const std::string& name, const fs::path& parent) {
  try {
    validate_session_name(name);
  } catch (const InputError& error) {
    return error.what();
  }
  std::error_code error;
  if (fs::symlink_status(parent / name, error).type() != fs::file_type::not_found) {
    return "a session named '" + printable(name) + "' exists already";
  }
  return {};
}

fs::path rename_session(const fs::path& directory, const std::string& new_name) {
  const fs::path parent = directory.parent_path();
  if (const std::string why = session_name_refusal(new_name, parent); !why.empty()) throw InputError(why);
  // The lock first, then the manifest through the same handle: read before the lock, a manifest that a
  // run committed in between would be written back older, and its newest iterations taken for the
  // leftovers of an interrupted save (and deleted) by the next resume.
  const DirectoryHandle handle = open_session_directory(directory);
  const SessionLock lock(handle, "bellows sessions rename");  // not while a run or a console writes it
  SessionManifest manifest = load_manifest(handle);
  // Not const: returned, so moved out.
  fs::path target = parent / new_name;
  std::error_code error;
  fs::rename(directory, target, error);
  if (error)
    throw_file_error("cannot rename " + printable(directory.string()) + " to " + printable(target.string()),
                     error.value());
  manifest.name = new_name;  // the manifest names its session too
  manifest.updated_utc = utc_now();
  // Through the session's own descriptor, by the one safe writer: a link planted at any name in
  // it is replaced or refused, never written through.
  write_file_atomic_at(DirectoryHandle::open(target), session_layout::kManifest, format_manifest(manifest));
  sync_directory(parent.empty() ? fs::path(".") : parent);
  return target;
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
  throw InputError(
      "session " + printable(path_or_name) + ": no such directory" +
      (data_dir.empty() ? std::string() : " (nor a session of that name in " + printable(data_dir.string()) + ")"));
}

SessionManifest load_manifest(const fs::path& directory) { return load_manifest(open_session_directory(directory)); }

SessionManifest load_manifest(const DirectoryHandle& directory) {
  SessionIntegrity ignored;
  const std::string text = read_session_file({directory, {}, {}}, session_layout::kManifest,
                                             session_layout::kMostManifestBytes, "", ignored);
  return parse_manifest(text, describe_session(directory.path()) + ": " + session_layout::kManifest);
}

Session load_session(const fs::path& directory) { return load_session(open_session_directory(directory)); }

namespace {

// Which manifest the directory holds now: a writer commits by renaming a new one over it, so a
// commit changes the inode (and the time of the change). Zeros when it cannot be seen.
std::tuple<ino_t, std::int64_t, long> manifest_identity(const DirectoryHandle& directory) {
  struct stat status {};
  if (::fstatat(directory.fd(), session_layout::kManifest, &status, AT_SYMLINK_NOFOLLOW) != 0) return {0, 0, 0};
  return {status.st_ino, static_cast<std::int64_t>(status.st_mtim.tv_sec), status.st_mtim.tv_nsec};
}

// A reader needs no lock, so a writer (the console, a run) may commit while it reads: the manifest
// it read can name a file the commit then removed (a correction's older revision). When the
// manifest changed while a read failed, the read is taken again from the new one (a few times: a
// writer commits at most a few times a second); a failure over an unchanged manifest is the
// session's own, reported as it is.
Session load_session_settled(const DirectoryHandle& directory, const std::vector<int>* only) {
  constexpr int kReads = 8;
  for (int read = 1;; ++read) {
    const auto before = manifest_identity(directory);
    try {
      return load_session_part(directory, only);
    } catch (const InputError&) {
      if (read == kReads || manifest_identity(directory) == before) throw;
    }
  }
}

}  // namespace

Session load_session(const DirectoryHandle& directory) { return load_session_settled(directory, nullptr); }

Session load_session_iterations(const fs::path& directory, const std::vector<int>& only) {
  return load_session_settled(open_session_directory(directory), &only);
}

namespace {

Session load_session_part(const DirectoryHandle& directory, const std::vector<int>* only) {
  Session session;
  session.directory = directory.path();
  session.manifest = load_manifest(directory);
  const SessionFolders folders{directory, session_folder(directory, session_layout::kIterations),
                               session_folder(directory, session_layout::kFaults)};
  const SessionManifest& m = session.manifest;
  const Configuration& config = m.configuration;
  const int samples = m.trajectory_samples;
  const auto rows = static_cast<std::size_t>(samples);
  const std::string where = describe_session(directory.path()) + ": ";
  SessionIntegrity& integrity = session.integrity;
  const int joints = m.joints;
  const std::vector<std::string> trajectory_names = trajectory_header(joints), samples_names = samples_header(joints),
                                 telemetry_names = telemetry_header(joints);
  session.trajectory = parse_trajectory_csv_file(
      read_session_file(folders, session_layout::kTrajectory, csv_size_limit(header_views(trajectory_names), rows + 1),
                        m.trajectory_sha256, integrity),
      where + session_layout::kTrajectory, m.trajectory_name, samples, config.timing.sample_s(), config.trajectory,
      joints);
  session.iterations.resize(m.iterations.size());
  for (std::size_t i = 0; i < m.iterations.size(); ++i) {
    const int index = static_cast<int>(i);
    if (only != nullptr && std::find(only->begin(), only->end(), index) == only->end()) continue;
    IterationData& data = session.iterations[i];
    const IterationEntry& entry = m.iterations[i];
    const std::string samples_file = session_layout::samples_file(index, entry.samples_revision);
    const std::string telemetry_file = session_layout::telemetry_file(index);
    const std::size_t ticks = rows * static_cast<std::size_t>(config.timing.ticks_per_sample);
    parse_samples_csv(read_session_file(folders, samples_file, csv_size_limit(header_views(samples_names), rows + 1),
                                        entry.samples_sha256, integrity),
                      where + samples_file, samples, config.timing.sample_s(), data, joints);
    parse_telemetry_csv(read_session_file(folders, telemetry_file, csv_size_limit(header_views(telemetry_names), ticks),
                                          entry.telemetry_sha256, integrity),
                        where + telemetry_file, samples, config.timing.ticks_per_sample, config.timing.tick_s, data);
    // The files and the manifest must tell the same story. With several joints the manifest's RMS
    // is the run's overall one (every joint and sample; `--json`'s "rms_deg"), or joint 1's.
    const double listed = entry.summary.rms_deg;
    const auto agrees = [&](double rms) { return std::abs(rms - listed) <= 1e-9 * std::max(1.0, listed); };
    const double rms = data.record.rms_error_deg();
    if (!agrees(rms) && !(joints > 1 && agrees(overall_rms_deg(data.record)))) {
      throw InputError(where + samples_file + ": its RMS error " +
                       std::to_string(joints > 1 ? overall_rms_deg(data.record) : rms) +
                       " deg differs from the manifest's " + std::to_string(listed) + " deg");
    }
  }
  for (std::size_t i = 0; only == nullptr && i < m.black_boxes.size(); ++i) {
    const BlackBoxEntry& entry = m.black_boxes[i];
    const std::string file = session_layout::black_box_file(static_cast<int>(i));
    const std::size_t limit =
        csv_size_limit(header_views(black_box_header(m.joints)), static_cast<std::size_t>(entry.ticks));
    session.black_boxes.push_back(parse_black_box_csv(read_session_file(folders, file, limit, entry.sha256, integrity),
                                                      where + file, entry.ticks));
  }
  session.dropped = describe_dropped(find_uncommitted_files(directory, m));
  return session;
}

}  // namespace

std::string dropped_line(const Session& session) {
  if (session.dropped.empty()) return "";
  const auto n = static_cast<long long>(session.iterations.size());
  return describe_session(session.directory) +
         ": a save was interrupted; dropped what it had not committed: " + session.dropped +
         "; this is its last committed state (" + std::to_string(n) + (n == 1 ? " iteration)" : " iterations)");
}

void save_session(const Session& session, const fs::path& directory) {
  create_session_directory(directory, session.manifest, session.trajectory, session.iterations, "bellows save",
                           session.black_boxes);
}

DirectoryHandle open_session_directory(const fs::path& directory) {
  try {
    return DirectoryHandle::open(directory);
  } catch (const InputError& error) {
    throw InputError("session " + std::string(error.what()));
  }
}

std::vector<SessionListing> list_sessions(const fs::path& data_dir) {
  std::vector<SessionListing> listings;
  std::error_code error;
  if (!fs::is_directory(data_dir, error)) return listings;
  const DirectoryHandle data = DirectoryHandle::open(data_dir);
  for (const auto& entry : fs::directory_iterator(data_dir, error)) {
    const std::string name = entry.path().filename().string();
    // A link is listed (and refused): it may point at a session, but the session's files are not inside it.
    if (name.empty() || name.front() == '.' || !(entry.is_symlink(error) || entry.is_directory(error))) continue;
    SessionListing listing;
    listing.directory = entry.path();
    try {
      const std::optional<DirectoryHandle> session = data.subdirectory(name);
      if (!session) continue;  // gone meanwhile
      listing.manifest = load_manifest(*session);
    } catch (const InputError& load_error) {
      const std::string what = load_error.what();
      listing.error = what.rfind("session ", 0) == 0 ? what : describe_session(entry.path()) + ": " + what;
    } catch (const std::exception& load_error) {  // e.g. out of memory: this session only
      listing.error = describe_session(entry.path()) + ": cannot be read: " + load_error.what();
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
