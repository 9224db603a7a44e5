#include "app/trajectory_file.hpp"

#include <charconv>
#include <cmath>
#include <filesystem>
#include <sstream>
#include <vector>

#include "app/device_factory.hpp"
#include "engine/model/arm_chain_parameters.hpp"
#include "engine/base/errors.hpp"
#include "engine/base/units.hpp"
#include "engine/base/printable_text.hpp"
#include "sessions/file_access.hpp"

namespace bellows {
namespace {

// 64 MiB: about a million samples (six hours at 50 Hz), far beyond any trial, yet a bound that
// keeps a wrong file (a disk image, /dev/zero behind a link) from being read whole.
constexpr std::size_t kMostTrajectoryBytes = std::size_t{64} << 20;
// Spreadsheets on Windows start UTF-8 files with it.
constexpr std::string_view kUtf8ByteOrderMark = "\xef\xbb\xbf";

double parse_number(const std::string& field, const std::string& where) {
  const std::string text(trim(field));
  double value = 0.0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (text.empty() || error != std::errc() || end != text.data() + text.size()) {
    throw InputError(where + ": '" + printable(text) + "' is not a number");
  }
  return value;
}

std::vector<std::string> split_fields(const std::string& line) {
  std::vector<std::string> fields;
  std::size_t begin = 0;
  for (std::size_t comma = line.find(','); comma != std::string::npos; comma = line.find(',', begin)) {
    fields.push_back(line.substr(begin, comma - begin));
    begin = comma + 1;
  }
  fields.push_back(line.substr(begin));
  return fields;
}

std::string joint_column(int joint) {
  std::string column = "q";  // appended piece by piece: GCC 12 warns falsely on "q" + std::string (its bug 105329)
  column += std::to_string(joint);
  column += "_deg";
  return column;
}

/// The columns a header names, "time_s,angle_deg" or "time_s,q1_deg,...,qJ_deg": their joint count.
int joints_of_header(const std::string& header, const std::string& where) {
  if (header == "time_s,angle_deg") return 1;
  const std::vector<std::string> fields = split_fields(header);
  if (fields.size() < 2 || trim(fields[0]) != "time_s" || trim(fields[1]) != joint_column(1)) {
    throw InputError(where +
                     ": the header must be 'time_s,angle_deg' or 'time_s,q1_deg,...' (one column per joint), found '" +
                     printable(header) + "'");
  }
  for (std::size_t column = 2; column < fields.size(); ++column) {
    const std::string wanted = joint_column(static_cast<int>(column));
    if (trim(fields[column]) != wanted) {
      throw InputError(where + ": column " + std::to_string(column + 1) + " of the header must be '" + wanted +
                       "', found '" + printable(trim(fields[column])) + "'");
    }
  }
  const int joints = static_cast<int>(fields.size()) - 1;
  if (joints > kMaxJoints) {
    throw InputError(where + ": " + std::to_string(joints) + " joint columns, at most " + std::to_string(kMaxJoints) +
                     " joints (q1_deg to " + joint_column(kMaxJoints) + ")");
  }
  return joints;
}

/// What a row must hold, for messages: "two fields 'time_s,angle_deg'", "3 fields 'time_s,q1_deg,q2_deg'".
std::string expected_fields(int joints) {
  if (joints == 1) return "two fields 'time_s,angle_deg'";
  std::string columns = "time_s";
  for (int joint = 1; joint <= joints; ++joint) {
    columns += ',';
    columns += joint_column(joint);
  }
  return std::to_string(joints + 1) + " fields '" + columns + "'";
}

// The shortest text that reads back to the same double.
std::string shortest(double value) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  return std::string(buffer, result.ptr);
}

}  // namespace

Trajectory parse_trajectory_csv(const std::string& text, const std::string& source_name, double sample_time_s,
                                const TrajectoryLimits& limits) {
  const bool byte_order_mark = std::string_view(text).substr(0, kUtf8ByteOrderMark.size()) == kUtf8ByteOrderMark;
  std::istringstream in(byte_order_mark ? text.substr(kUtf8ByteOrderMark.size()) : text);
  const std::string source = printable(source_name);
  std::string line;
  std::getline(in, line);
  const int joints = joints_of_header(std::string(trim(line)), "trajectory " + source + ": line 1");
  std::vector<double> times;
  std::vector<std::vector<double>> angles(static_cast<std::size_t>(joints));
  int line_number = 1;
  while (std::getline(in, line)) {
    ++line_number;
    if (trim(line).empty()) continue;
    const std::string where = "trajectory " + source + ": line " + std::to_string(line_number);
    const std::vector<std::string> fields = split_fields(line);
    if (fields.size() != static_cast<std::size_t>(joints) + 1) {
      throw InputError(where + ": expected " + expected_fields(joints) + ", found " + std::to_string(fields.size()));
    }
    times.push_back(parse_number(fields[0], where));
    for (int joint = 0; joint < joints; ++joint) {
      angles[static_cast<std::size_t>(joint)].push_back(
          parse_number(fields[static_cast<std::size_t>(joint) + 1], where));
    }
  }
  const std::string name = std::filesystem::path(source_name).stem().string();
  try {
    return trajectory_from_joint_samples(name, times, angles, sample_time_s, limits);
  } catch (const InputError& error) {
    throw InputError("trajectory " + source + ": " + error.what());
  }
}

void require_driven_joints(const Trajectory& trajectory, const ArmParameters& arm) {
  if (!arm.has_chain()) {
    require_trajectory_joints(trajectory, 1, "[arm] preset");
  } else {
    require_trajectory_joints(trajectory, arm_joint_count(arm), arm.name());
  }
}

std::string trajectory_csv(const Trajectory& trajectory) {
  std::string text = "time_s";
  if (trajectory.joints() == 1) {
    text += ",angle_deg";
  } else {
    for (int joint = 1; joint <= trajectory.joints(); ++joint) {
      text += ',';
      text += joint_column(joint);
    }
  }
  text += "\n";
  for (Eigen::Index k = 0; k <= trajectory.learning_samples(); ++k) {
    // Time to the nanosecond: the reader's tolerance is a microsecond, and 0.06 stays "0.06".
    text += shortest(std::round(static_cast<double>(k) * trajectory.sample_time_s * 1e9) / 1e9);
    for (int joint = 0; joint < trajectory.joints(); ++joint) {
      text += ',';
      text += shortest(trajectory.joint(joint)(k) * kDegPerRad);
    }
    text += "\n";
  }
  return text;
}

void write_trajectory_file(const std::filesystem::path& path, const Trajectory& trajectory, Replace replace) {
  if (std::filesystem::is_directory(path)) {
    throw InputError("trajectory file " + printable(path.string()) + " is a directory: name a file in it");
  }
  const std::filesystem::path directory = path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
  write_file_atomic_at(DirectoryHandle::open(directory), path.filename().string(), trajectory_csv(trajectory),
                       DirectorySync::kNow, replace);
}

Trajectory load_trajectory_file(const std::string& path, double sample_time_s, const TrajectoryLimits& limits) {
  // A FIFO, a device or a directory is refused without blocking; a link the operator names is followed.
  return parse_trajectory_csv(read_regular_file(path, kMostTrajectoryBytes, "trajectory"), path, sample_time_s, limits);
}

Trajectory resolve_trajectory(const std::string& name_or_path, double sample_time_s, const TrajectoryLimits& limits) {
  const bool looks_like_file =
      name_or_path.find('/') != std::string::npos || std::filesystem::path(name_or_path).extension() == ".csv";
  if (looks_like_file) return load_trajectory_file(name_or_path, sample_time_s, limits);
  Trajectory trajectory = library_trajectory(name_or_path, sample_time_s);
  validate_trajectory(trajectory, limits);
  return trajectory;
}

}  // namespace bellows
