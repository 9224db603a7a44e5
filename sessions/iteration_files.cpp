#include "sessions/iteration_files.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "engine/base/errors.hpp"
#include "engine/base/units.hpp"
#include "sessions/csv_table.hpp"
#include "sessions/record_columns.hpp"

namespace bellows {
namespace {

// The engine's own conversion (engine/trial/trajectory.cpp), so degrees read back bit for bit.
// Times are k * T; a hand-edited or foreign file may round them.
constexpr double kTimeTolerance_s = 1e-6;

void expect_rows(const Eigen::VectorXd& column, Eigen::Index rows, const std::string& source, const char* what) {
  if (column.size() != rows) {
    throw InputError(source + ": expected " + std::to_string(rows) + " rows (" + what + "), found " +
                     std::to_string(column.size()));
  }
}

void expect_uniform_time(const Eigen::VectorXd& time_s, double step_s, const std::string& source) {
  for (Eigen::Index k = 0; k < time_s.size(); ++k) {
    const double expected = static_cast<double>(k) * step_s;
    if (std::abs(time_s(k) - expected) > kTimeTolerance_s) {
      throw InputError(source + ": line " + std::to_string(k + 2) + ": time_s = " + std::to_string(time_s(k)) +
                       ", expected " + std::to_string(expected) + " (uniform sampling every " + std::to_string(step_s) +
                       " s)");
    }
  }
}

}  // namespace

double radians_from_degrees(double angle_deg) { return angle_deg * kRadPerDeg; }

Eigen::VectorXd degrees_of(const Eigen::VectorXd& angle_rad) {
  return angle_rad.unaryExpr([](double rad) { return degrees_for_exact_radians(rad); });
}

double degrees_for_exact_radians(double angle_rad) {
  // Prefer the short decimal a person would write ("30", not "29.999999999999996") when it reads
  // back to the same radians; else the nearest double that does; else the plain quotient.
  const double estimate = angle_rad / kRadPerDeg;
  if (!std::isfinite(estimate)) return estimate;
  char text[32];
  const auto printed = std::to_chars(text, text + sizeof text, estimate, std::chars_format::general, 15);
  double rounded = 0.0;
  std::from_chars(text, printed.ptr, rounded);
  if (rounded * kRadPerDeg == angle_rad) return rounded;
  if (estimate * kRadPerDeg == angle_rad) return estimate;
  double up = estimate, down = estimate;
  for (int step = 0; step < 4; ++step) {
    up = std::nextafter(up, std::numeric_limits<double>::infinity());
    if (up * kRadPerDeg == angle_rad) return up;
    down = std::nextafter(down, -std::numeric_limits<double>::infinity());
    if (down * kRadPerDeg == angle_rad) return down;
  }
  return estimate;
}

Eigen::VectorXd rounded_times(const Eigen::VectorXd& time_s) {
  // k * T carries float noise (0.8200000000000001); nanoseconds are far finer than any tick.
  return time_s.unaryExpr([](double t) { return std::round(t * 1e9) / 1e9; });
}

namespace {

void append_columns(std::string& out, const std::vector<std::string>& names,
                    const std::vector<Eigen::VectorXd>& values) {
  std::vector<CsvColumn> columns;
  columns.reserve(names.size());
  for (std::size_t c = 0; c < names.size(); ++c) columns.push_back({names[c], &values[c]});
  append_csv(out, columns);
}

}  // namespace

const std::vector<std::string_view>& trajectory_columns() {
  static const std::vector<std::string> names = trajectory_header(1);
  static const std::vector<std::string_view> views = header_views(names);
  return views;
}

const std::vector<std::string_view>& samples_columns() {
  static const std::vector<std::string> names = samples_header(1);
  static const std::vector<std::string_view> views = header_views(names);
  return views;
}

const std::vector<std::string_view>& telemetry_columns() {
  static const std::vector<std::string> names = telemetry_header(1);
  static const std::vector<std::string_view> views = header_views(names);
  return views;
}

std::string format_trajectory_csv(const Trajectory& trajectory) {
  std::string out;
  append_columns(out, trajectory_header(trajectory.joints()), trajectory_file_values(trajectory));
  return out;
}

Trajectory parse_trajectory_csv_file(std::string_view text, const std::string& source, const std::string& name,
                                     int learning_samples, double sample_time_s, const TrajectoryLimits& limits,
                                     int joints) {
  const std::vector<std::string> header = trajectory_header(joints);
  const std::vector<Eigen::VectorXd> columns = parse_csv(text, header_views(header), source);
  expect_rows(columns[0], learning_samples + 1, source, "the manifest's learning_samples + 1");
  const std::vector<double> times(columns[0].begin(), columns[0].end());
  std::vector<std::vector<double>> degrees;
  for (std::size_t c = 1; c < columns.size(); ++c) degrees.emplace_back(columns[c].begin(), columns[c].end());
  try {
    if (joints == 1) return trajectory_from_samples(name, times, degrees[0], sample_time_s, limits);
    return trajectory_from_joint_samples(name, times, degrees, sample_time_s, limits);
  } catch (const InputError& error) {
    throw InputError(source + ": " + error.what());
  }
}

std::string format_samples_csv(const TrialRecord& record, const Eigen::MatrixXd& next_corrections_bar) {
  std::string out;
  append_columns(out, samples_header(record.joint_count()), samples_file_values(record, next_corrections_bar));
  return out;
}

std::string format_telemetry_csv(const TrialRecord& record) {
  std::string out;
  append_columns(out, telemetry_header(record.joint_count()), telemetry_file_values(record));
  return out;
}

void parse_samples_csv(std::string_view text, const std::string& source, int learning_samples, double sample_time_s,
                       IterationData& data, int joints) {
  const std::vector<std::string> header = samples_header(joints);
  std::vector<Eigen::VectorXd> c = parse_csv(text, header_views(header), source);
  expect_rows(c[0], learning_samples + 1, source, "the trajectory's learning samples + 1");
  expect_uniform_time(c[0], sample_time_s, source);
  TrialRecord& record = data.record;
  record.learning_samples = learning_samples;
  record.complete = true;
  const Eigen::MatrixXd next = samples_from_file_values(c, joints, record);
  data.set_next_corrections(next.topRows(learning_samples));
}

void parse_telemetry_csv(std::string_view text, const std::string& source, int learning_samples, int ticks_per_sample,
                         double tick_s, IterationData& data) {
  if (data.record.joint_count() < 1) {  // a caller's mistake, not the file's: there is nothing to fill
    throw std::logic_error("parse_telemetry_csv: the record has no joints (read its samples first)");
  }
  const std::vector<std::string> header = telemetry_header(data.record.joint_count());
  std::vector<Eigen::VectorXd> c = parse_csv(text, header_views(header), source);
  expect_rows(c[0], static_cast<Eigen::Index>(learning_samples) * ticks_per_sample, source,
              "learning samples times ticks per sample");
  expect_uniform_time(c[0], tick_s, source);
  telemetry_from_file_values(c, data.record);
}

}  // namespace bellows
