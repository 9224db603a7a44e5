#include "sessions/iteration_files.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <numbers>

#include "engine/errors.hpp"
#include "engine/units.hpp"
#include "sessions/csv_table.hpp"

namespace bellows {
namespace {

// The engine's own conversion (engine/trajectory.cpp), so degrees read back bit for bit.
// Times are k * T; a hand-edited or foreign file may round them.
constexpr double kTimeTolerance_s = 1e-6;

Eigen::VectorXd to_radians(const Eigen::VectorXd& degrees) { return degrees * kRadPerDeg; }

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

const std::vector<std::string_view>& trajectory_columns() {
  static const std::vector<std::string_view> columns = {"time_s", "angle_deg"};
  return columns;
}

const std::vector<std::string_view>& samples_columns() {
  static const std::vector<std::string_view> columns = {
      "time_s",         "angle_setpoint_deg", "angle_deg",      "error_deg",
      "u_pid_bar",      "u_ilc_bar",          "u_tot_bar",      "pressure_a_bar",
      "pressure_b_bar", "pressure_a_setpoint_bar", "pressure_b_setpoint_bar", "u_ilc_next_bar"};
  return columns;
}

const std::vector<std::string_view>& telemetry_columns() {
  static const std::vector<std::string_view> columns = {
      "time_s",       "angle_deg",     "pressure_a_bar", "pressure_b_bar", "supply_bar",   "pressure_a_setpoint_bar",
      "pressure_b_setpoint_bar", "inlet_a_duty", "outlet_a_duty", "inlet_b_duty", "outlet_b_duty"};
  return columns;
}

std::string format_trajectory_csv(const Trajectory& trajectory) {
  const Eigen::Index rows = trajectory.angle_rad.size();
  Eigen::VectorXd times(rows);
  for (Eigen::Index k = 0; k < rows; ++k) times(k) = static_cast<double>(k) * trajectory.sample_time_s;
  times = rounded_times(times);
  const Eigen::VectorXd degrees = degrees_of(trajectory.angle_rad);
  std::string out;
  append_csv(out, {{"time_s", &times}, {"angle_deg", &degrees}});
  return out;
}

Trajectory parse_trajectory_csv_file(std::string_view text, const std::string& source, const std::string& name,
                                     int learning_samples, double sample_time_s, const TrajectoryLimits& limits) {
  const std::vector<Eigen::VectorXd> columns = parse_csv(text, trajectory_columns(), source);
  expect_rows(columns[0], learning_samples + 1, source, "the manifest's learning_samples + 1");
  const std::vector<double> times(columns[0].begin(), columns[0].end());
  const std::vector<double> degrees(columns[1].begin(), columns[1].end());
  try {
    return trajectory_from_samples(name, times, degrees, sample_time_s, limits);
  } catch (const InputError& error) {
    throw InputError(source + ": " + error.what());
  }
}

std::string format_samples_csv(const TrialRecord& record, const Eigen::VectorXd& next_correction_bar) {
  const TrialSamples& s = record.samples;
  const Eigen::Index rows = s.time_s.size();
  const Eigen::Index learned = std::min(rows, next_correction_bar.size());
  Eigen::VectorXd next = Eigen::VectorXd::Zero(rows);
  next.head(learned) = next_correction_bar.head(learned);
  const Eigen::VectorXd setpoint_deg = degrees_of(s.setpoint_rad), angle_deg = degrees_of(s.angle_rad),
                        error_deg = degrees_of(s.error_rad);
  const Eigen::VectorXd time_s = rounded_times(s.time_s);
  const auto& n = samples_columns();
  std::string out;
  append_csv(out, {{n[0], &time_s},
                   {n[1], &setpoint_deg},
                   {n[2], &angle_deg},
                   {n[3], &error_deg},
                   {n[4], &s.u_pid_bar},
                   {n[5], &s.u_ilc_bar},
                   {n[6], &s.u_total_bar},
                   {n[7], &s.pressure_a_bar},
                   {n[8], &s.pressure_b_bar},
                   {n[9], &s.setpoint_a_bar},
                   {n[10], &s.setpoint_b_bar},
                   {n[11], &next}});
  return out;
}

std::string format_telemetry_csv(const TrialRecord& record) {
  const TrialTicks& t = record.ticks;
  const Eigen::VectorXd angle_deg = degrees_of(t.angle_rad);
  const Eigen::VectorXd time_s = rounded_times(t.time_s);
  const auto& n = telemetry_columns();
  std::string out;
  append_csv(out, {{n[0], &time_s},
                   {n[1], &angle_deg},
                   {n[2], &t.pressure_a_bar},
                   {n[3], &t.pressure_b_bar},
                   {n[4], &t.supply_bar},
                   {n[5], &t.setpoint_a_bar},
                   {n[6], &t.setpoint_b_bar},
                   {n[7], &t.inlet_a},
                   {n[8], &t.outlet_a},
                   {n[9], &t.inlet_b},
                   {n[10], &t.outlet_b}});
  return out;
}

void parse_samples_csv(std::string_view text, const std::string& source, int learning_samples, double sample_time_s,
                       IterationData& data) {
  std::vector<Eigen::VectorXd> c = parse_csv(text, samples_columns(), source);
  expect_rows(c[0], learning_samples + 1, source, "the trajectory's learning samples + 1");
  expect_uniform_time(c[0], sample_time_s, source);
  TrialRecord& record = data.record;
  TrialSamples& s = record.samples;
  record.learning_samples = learning_samples;
  record.complete = true;
  s.time_s = std::move(c[0]);
  s.setpoint_rad = to_radians(c[1]);
  s.angle_rad = to_radians(c[2]);
  s.error_rad = to_radians(c[3]);
  s.u_pid_bar = std::move(c[4]);
  s.u_ilc_bar = std::move(c[5]);
  s.u_total_bar = std::move(c[6]);
  s.pressure_a_bar = std::move(c[7]);
  s.pressure_b_bar = std::move(c[8]);
  s.setpoint_a_bar = std::move(c[9]);
  s.setpoint_b_bar = std::move(c[10]);
  data.next_correction_bar = c[11].head(learning_samples);
}

void parse_telemetry_csv(std::string_view text, const std::string& source, int learning_samples, int ticks_per_sample,
                         double tick_s, IterationData& data) {
  std::vector<Eigen::VectorXd> c = parse_csv(text, telemetry_columns(), source);
  expect_rows(c[0], static_cast<Eigen::Index>(learning_samples) * ticks_per_sample, source,
              "learning samples times ticks per sample");
  expect_uniform_time(c[0], tick_s, source);
  TrialTicks& t = data.record.ticks;
  t.time_s = std::move(c[0]);
  t.angle_rad = to_radians(c[1]);
  t.pressure_a_bar = std::move(c[2]);
  t.pressure_b_bar = std::move(c[3]);
  t.supply_bar = std::move(c[4]);
  t.setpoint_a_bar = std::move(c[5]);
  t.setpoint_b_bar = std::move(c[6]);
  t.inlet_a = std::move(c[7]);
  t.outlet_a = std::move(c[8]);
  t.inlet_b = std::move(c[9]);
  t.outlet_b = std::move(c[10]);
}

}  // namespace bellows
