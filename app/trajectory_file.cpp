#include "app/trajectory_file.hpp"

#include <charconv>
#include <filesystem>
#include <sstream>
#include <vector>

#include "engine/errors.hpp"
#include "engine/printable_text.hpp"
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

}  // namespace

Trajectory parse_trajectory_csv(const std::string& text, const std::string& source_name, double sample_time_s,
                                const TrajectoryLimits& limits) {
  const bool byte_order_mark = std::string_view(text).substr(0, kUtf8ByteOrderMark.size()) == kUtf8ByteOrderMark;
  std::istringstream in(byte_order_mark ? text.substr(kUtf8ByteOrderMark.size()) : text);
  const std::string source = printable(source_name);
  std::string line;
  if (!std::getline(in, line) || trim(line) != "time_s,angle_deg") {
    throw InputError("trajectory " + source + ": line 1: the header must be 'time_s,angle_deg', found '" +
                     printable(trim(line)) + "'");
  }
  std::vector<double> times, angles;
  int line_number = 1;
  while (std::getline(in, line)) {
    ++line_number;
    if (trim(line).empty()) continue;
    const std::string where = "trajectory " + source + ": line " + std::to_string(line_number);
    const auto comma = line.find(',');
    if (comma == std::string::npos || line.find(',', comma + 1) != std::string::npos) {
      throw InputError(where + ": expected two fields 'time_s,angle_deg'");
    }
    times.push_back(parse_number(line.substr(0, comma), where));
    angles.push_back(parse_number(line.substr(comma + 1), where));
  }
  const std::string name = std::filesystem::path(source_name).stem().string();
  try {
    return trajectory_from_samples(name, times, angles, sample_time_s, limits);
  } catch (const InputError& error) {
    throw InputError("trajectory " + source + ": " + error.what());
  }
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
