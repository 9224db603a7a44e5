// MATLAB exports (MAT v5 or v7.3) of a session through libmatio; see session_export.hpp.
#include <fcntl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <limits>
#include <memory>
#include <string>

#include <hdf5.h>
#include <matio.h>

#include "engine/rt/engine_state.hpp"
#include "engine/base/errors.hpp"
#include "engine/control/safety.hpp"
#include "sessions/atomic_file.hpp"
#include "sessions/black_box_file.hpp"
#include "sessions/file_access.hpp"
#include "sessions/iteration_files.hpp"
#include "sessions/manifest_json.hpp"
#include "sessions/record_columns.hpp"
#include "sessions/session_event_record.hpp"
#include "sessions/session_export.hpp"

namespace bellows {
namespace fs = std::filesystem;
namespace {

struct MatVarDeleter {
  void operator()(matvar_t* var) const { Mat_VarFree(var); }
};
using MatVar = std::unique_ptr<matvar_t, MatVarDeleter>;

/// MATLAB field names: a letter first, then letters, digits and underscores.
std::string matlab_name(const std::string& name) {
  std::string out;
  for (char c : name) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
    out += ok ? c : '_';
  }
  if (out.empty() || !((out[0] >= 'a' && out[0] <= 'z') || (out[0] >= 'A' && out[0] <= 'Z'))) out = "x" + out;
  return out;
}

MatVar column(const Eigen::VectorXd& values) {
  size_t dims[2] = {static_cast<size_t>(values.size()), 1};
  return MatVar(Mat_VarCreate(nullptr, MAT_C_DOUBLE, MAT_T_DOUBLE, 2, dims, const_cast<double*>(values.data()), 0));
}

MatVar scalar(double value) {
  size_t dims[2] = {1, 1};
  return MatVar(Mat_VarCreate(nullptr, MAT_C_DOUBLE, MAT_T_DOUBLE, 2, dims, &value, 0));
}

MatVar text(const std::string& value) {
  size_t dims[2] = {1, value.size()};
  return MatVar(Mat_VarCreate(nullptr, MAT_C_CHAR, MAT_T_UTF8, 2, dims, const_cast<char*>(value.data()), 0));
}

/// A struct (array) with the given fields; set them with set_field().
MatVar structure(const std::vector<std::string>& fields, size_t count = 1) {
  std::vector<const char*> names;
  names.reserve(fields.size() + 1);
  for (const std::string& field : fields) names.push_back(field.c_str());
  names.push_back(nullptr);
  size_t dims[2] = {1, count};
  return MatVar(Mat_VarCreateStruct2(nullptr, 2, dims, names.data()));
}

void set_field(matvar_t* parent, const std::string& field, size_t index, MatVar value) {
  if (value == nullptr) throw std::runtime_error("libmatio could not create field " + field);
  Mat_VarSetStructFieldByName(parent, field.c_str(), index, value.release());  // the parent owns it now
}

/// A struct of one column vector per field: a file's columns by their names (record_columns.hpp).
MatVar columns_struct(const std::vector<std::string>& fields, const std::vector<Eigen::VectorXd>& values) {
  MatVar out = structure(fields);
  for (std::size_t i = 0; i < fields.size(); ++i) set_field(out.get(), fields[i], 0, column(values[i]));
  return out;
}

MatVar samples_struct(const IterationData& data) {
  return columns_struct(samples_header(data.record.joint_count()),
                        samples_file_values(data.record, data.next_corrections_bar()));
}

MatVar telemetry_struct(const TrialRecord& record) {
  return columns_struct(telemetry_header(record.joint_count()), telemetry_file_values(record));
}

MatVar configuration_struct(const Configuration& config) {
  const nlohmann::ordered_json json = configuration_to_json(config);
  std::vector<std::string> sections;
  for (const auto& item : json.items()) sections.push_back(matlab_name(item.key()));
  MatVar out = structure(sections);
  std::size_t s = 0;
  for (const auto& [section, values] : json.items()) {
    std::vector<std::string> keys;
    for (const auto& item : values.items()) keys.push_back(matlab_name(item.key()));
    MatVar inner = structure(keys);
    std::size_t k = 0;
    for (const auto& [key, value] : values.items()) {
      set_field(inner.get(), keys[k++], 0,
                value.is_string() ? text(value.get<std::string>()) : scalar(value.get<double>()));
    }
    set_field(out.get(), sections[s++], 0, std::move(inner));
  }
  return out;
}

MatVar session_struct(const Session& session) {
  const SessionManifest& m = session.manifest;
  MatVar out = structure({"name", "program_version", "device", "started_utc", "updated_utc", "configuration",
                          "trajectory", "summary", "events"});
  set_field(out.get(), "name", 0, text(m.name));
  set_field(out.get(), "program_version", 0, text(m.program_version));
  set_field(out.get(), "device", 0, text(m.device));
  set_field(out.get(), "started_utc", 0, text(m.started_utc));
  set_field(out.get(), "updated_utc", 0, text(m.updated_utc));
  set_field(out.get(), "configuration", 0, configuration_struct(m.configuration));

  // The trajectory file's columns: time_s, angle_deg (one joint) or time_s, q1_deg, ... (several).
  const Trajectory& trajectory = session.trajectory;
  std::vector<std::string> trajectory_fields = trajectory_header(trajectory.joints());
  const std::vector<Eigen::VectorXd> trajectory_values = trajectory_file_values(trajectory);
  trajectory_fields.insert(trajectory_fields.begin(), "name");
  MatVar trajectory_var = structure(trajectory_fields);
  set_field(trajectory_var.get(), "name", 0, text(trajectory.name));
  for (std::size_t c = 0; c < trajectory_values.size(); ++c) {
    set_field(trajectory_var.get(), trajectory_fields[c + 1], 0, column(trajectory_values[c]));
  }
  set_field(out.get(), "trajectory", 0, std::move(trajectory_var));

  const auto n = static_cast<Eigen::Index>(m.iterations.size());
  Eigen::VectorXd iteration(n), rms(n), max_error(n), max_correction(n), saturated(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const IterationSummary& s = m.iterations[static_cast<std::size_t>(i)].summary;
    iteration(i) = s.iteration;
    rms(i) = s.rms_deg;
    max_error(i) = s.max_abs_error_deg;
    max_correction(i) = s.max_abs_correction_bar;
    saturated(i) = s.saturated_samples;
  }
  set_field(out.get(), "summary", 0,
            columns_struct({"iteration", "rms_deg", "max_abs_error_deg", "max_abs_correction_bar", "saturated_samples"},
                           {iteration, rms, max_error, max_correction, saturated}));

  // The event record's fields (session_event_record.hpp); an optional one only when some event has
  // it, NaN in the others (a struct array's elements share their fields).
  std::vector<const EventField*> event_fields;
  std::vector<std::string> event_names;
  for (const EventField& f : event_record_fields()) {
    if (f.optional && std::none_of(m.events.begin(), m.events.end(), f.known)) continue;
    event_fields.push_back(&f);
    event_names.emplace_back(f.name);
  }
  MatVar events = structure(event_names, m.events.size());
  for (std::size_t e = 0; e < m.events.size(); ++e) {
    for (const EventField* f : event_fields) {
      const std::string name(f->name);
      if (!f->known(m.events[e])) {
        set_field(events.get(), name, e, scalar(std::numeric_limits<double>::quiet_NaN()));
      } else {
        const nlohmann::ordered_json value = f->value(m.events[e]);
        set_field(events.get(), name, e, f->text ? text(value.get<std::string>()) : scalar(value.get<double>()));
      }
    }
  }
  set_field(out.get(), "events", 0, std::move(events));
  return out;
}

MatVar iterations_struct(const Session& session) {
  MatVar out = structure({"iteration", "rms_deg", "max_abs_error_deg", "max_abs_correction_bar", "saturated_samples",
                          "completed_utc", "samples", "telemetry"},
                         session.iterations.size());
  for (std::size_t i = 0; i < session.iterations.size(); ++i) {
    const IterationEntry& entry = session.manifest.iterations[i];
    set_field(out.get(), "iteration", i, scalar(entry.summary.iteration));
    set_field(out.get(), "rms_deg", i, scalar(entry.summary.rms_deg));
    set_field(out.get(), "max_abs_error_deg", i, scalar(entry.summary.max_abs_error_deg));
    set_field(out.get(), "max_abs_correction_bar", i, scalar(entry.summary.max_abs_correction_bar));
    set_field(out.get(), "saturated_samples", i, scalar(entry.summary.saturated_samples));
    set_field(out.get(), "completed_utc", i, text(entry.completed_utc));
    set_field(out.get(), "samples", i, samples_struct(session.iterations[i]));
    set_field(out.get(), "telemetry", i, telemetry_struct(session.iterations[i].record));
  }
  return out;
}

void write_named(mat_t* file, MatVar var, const char* name, const fs::path& path) {
  // Top-level variables need a name; Mat_VarFree releases it with the rest.
  var->name = strdup(name);
  errno = 0;
  if (Mat_VarWrite(file, var.get(), MAT_COMPRESSION_ZLIB) != 0) {
    // libmatio says only that it failed; the system's reason (a full disk) is in errno, if anywhere.
    const int why = errno;
    const std::string what = "cannot write variable '" + std::string(name) + "' to " + path.string();
    if (why != 0) throw_file_error(what, why);
    throw InputError(what);
  }
}

/// An n x 1 cell array of strings: how MATLAB, Octave and scipy hold a column of names.
MatVar names_column(const std::vector<std::string>& names) {
  size_t dims[2] = {names.size(), 1};
  MatVar out(Mat_VarCreate(nullptr, MAT_C_CELL, MAT_T_CELL, 2, dims, nullptr, 0));
  for (std::size_t i = 0; i < names.size(); ++i)
    Mat_VarSetCell(out.get(), static_cast<int>(i), text(names[i]).release());
  return out;
}

/// The black boxes, a 1 x faults struct array; `ticks` holds the black-box file's columns.
MatVar black_boxes_struct(const Session& session) {
  const std::size_t count = session.black_boxes.size();
  MatVar out = structure({"fault", "iteration", "time_utc", "ticks"}, count);
  for (std::size_t b = 0; b < count; ++b) {
    const BlackBoxEntry& entry = session.manifest.black_boxes[b];
    set_field(out.get(), "fault", b, text(entry.fault));
    set_field(out.get(), "iteration", b, scalar(entry.iteration));
    set_field(out.get(), "time_utc", b, text(entry.time_utc));
    const std::vector<Eigen::VectorXd> values = black_box_values(session.black_boxes[b]);
    const std::vector<std::string> fields = black_box_header(black_box_joints(session.black_boxes[b]));
    MatVar ticks = structure(fields);
    for (std::size_t c = 0; c < fields.size(); ++c) {
      if (c == kBlackBoxStateColumn || c == kBlackBoxFaultColumn) {
        std::vector<std::string> names;
        for (Eigen::Index k = 0; k < values[c].size(); ++k) {
          const auto code = static_cast<std::uint8_t>(values[c](k));
          names.emplace_back(c == kBlackBoxStateColumn ? to_string(static_cast<EngineState>(code))
                                                       : fault_name(static_cast<FaultCode>(code)));
        }
        set_field(ticks.get(), fields[c], 0, names_column(names));
      } else {
        set_field(ticks.get(), fields[c], 0, column(values[c]));
      }
    }
    set_field(out.get(), "ticks", b, std::move(ticks));
  }
  return out;
}

/// Writes the session's variables into `file` and closes it; InputError naming `path` if libmatio fails.
void finish_mat_file(mat_t* file, const Session& session, const fs::path& path) {
  try {
    write_named(file, session_struct(session), "session", path);
    write_named(file, iterations_struct(session), "iterations", path);
    write_named(file, black_boxes_struct(session), "black_boxes", path);
  } catch (...) {
    Mat_Close(file);
    throw;
  }
  errno = 0;
  if (Mat_Close(file) != 0) {
    const int why = errno;
    const std::string what = "cannot write " + path.string() + " (libmatio could not finish it)";
    if (why != 0) throw_file_error(what, why);
    throw InputError(what);
  }
}

/// MAT v5: libmatio writes through its own stdio into memory (a memfd, reached by its
/// /proc/self/fd name), and the one safe writer writes those bytes out (exclusive temporary,
/// fsync, rename, fsync of the folder): nothing of libmatio's touches the folder.
void export_mat5(const Session& session, const fs::path& path, Replace replace) {
  const FileDescriptor memory(::memfd_create("bellows-mat-export", MFD_CLOEXEC));
  if (memory.get() < 0)
    throw EnvironmentError(std::string("cannot make the MAT file in memory: ") + std::strerror(errno));
  const std::string in_memory = "/proc/self/fd/" + std::to_string(memory.get());
  mat_t* file = Mat_CreateVer(in_memory.c_str(), nullptr, MAT_FT_MAT5);
  if (file == nullptr) throw InputError("cannot create " + path.string() + " (libmatio could not open it for writing)");
  finish_mat_file(file, session, path);
  std::string bytes;
  char buffer[1 << 16];
  for (off_t at = 0;;) {
    const ssize_t got = ::pread(memory.get(), buffer, sizeof buffer, at);
    if (got < 0 && errno == EINTR) continue;
    if (got < 0)
      throw EnvironmentError("cannot read the MAT file back from memory: " + std::string(std::strerror(errno)));
    if (got == 0) break;
    bytes.append(buffer, static_cast<std::size_t>(got));
    at += got;
  }
  write_file_atomic(path, bytes, DirectorySync::kNow, replace);
}

/// MAT v7.3 (for sessions beyond v5's 2 GB a variable: not held in memory): HDF5 needs a real
/// path (it resolves links, so a memfd's name will not do), so libmatio writes into a folder made
/// for it alone (0700, unpredictable name) beside the output, where nothing can be planted, and
/// the safe writer's last steps publish it: fsync, rename (refused over an existing file without
/// --force), fsync of the folder.
void export_mat73(const Session& session, const fs::path& path, Replace replace) {
  const fs::path directory = path.parent_path().empty() ? fs::path(".") : path.parent_path();
  const DirectoryHandle folder = DirectoryHandle::open(directory);
  const PrivateTemporaryDirectory work(folder, path.filename().string());
  const std::string name = path.filename().string();
  mat_t* file = Mat_CreateVer((work.path() / name).c_str(), nullptr, MAT_FT_MAT73);
  if (file == nullptr) throw InputError("cannot create " + path.string() + " (libmatio could not open it for writing)");
  finish_mat_file(file, session, path);
  {
    const std::optional<FileDescriptor> fd = open_regular_file_at(work.handle(), name, O_RDONLY);
    if (!fd || ::fsync(fd->get()) != 0) throw_file_error("cannot flush " + path.string(), errno);
  }
  publish_file_at(work.handle(), name, folder, name, replace);
  sync(folder);
}

}  // namespace

fs::path export_session_mat(const Session& session, const fs::path& path, MatVersion version, bool force) {
  check_export_targets(session, {path}, ".mat", force);
  // HDF5 (under MAT v7.3) cleans up at exit by closing every file still open; a file whose close
  // failed (a full disk under its last flush) is still listed, half closed, and HDF5 1.10 crashes on
  // it (SIGSEGV after the export's one line). Every file here is closed, or abandoned on purpose:
  // no clean-up at exit (this must come before any other HDF5 call; a second call is refused, harmless).
  H5dont_atexit();
  // HDF5 prints its own error stack to stderr by default; our errors say it in one line instead.
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  const Replace replace = force ? Replace::kAllowed : Replace::kRefused;
  if (version == MatVersion::kV73) export_mat73(session, path, replace);
  else export_mat5(session, path, replace);
  return path;
}

}  // namespace bellows
