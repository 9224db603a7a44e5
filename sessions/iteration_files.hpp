// The CSV files of a session: a trajectory (time_s, angle_deg), an iteration's ILC-rate samples
// with the correction learned from it, and its tick-rate telemetry. Columns and units are listed
// in docs/session-format.md. Angles are stored in degrees, written so that they read back to the
// very same radians wherever such a decimal exists (always for trajectories built from degrees).
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "engine/trajectory.hpp"
#include "sessions/session.hpp"

namespace bellows {

const std::vector<std::string_view>& trajectory_columns();
const std::vector<std::string_view>& samples_columns();
const std::vector<std::string_view>& telemetry_columns();

std::string format_trajectory_csv(const Trajectory& trajectory);
/// Checks the row count (N + 1), the uniform sampling at `sample_time_s` and the joint limits.
Trajectory parse_trajectory_csv_file(std::string_view text, const std::string& source, const std::string& name,
                                     int learning_samples, double sample_time_s, const TrajectoryLimits& limits);

/// The record's ILC-rate samples and the next correction (N values; 0 in the last row).
std::string format_samples_csv(const TrialRecord& record, const Eigen::VectorXd& next_correction_bar);
/// The record's tick-rate telemetry.
std::string format_telemetry_csv(const TrialRecord& record);

/// Fills `data` (record samples, next correction); checks N + 1 rows and the time column.
void parse_samples_csv(std::string_view text, const std::string& source, int learning_samples, double sample_time_s,
                       IterationData& data);
/// Fills `data.record.ticks`; checks N * ticks_per_sample rows and the time column.
void parse_telemetry_csv(std::string_view text, const std::string& source, int learning_samples, int ticks_per_sample,
                         double tick_s, IterationData& data);

/// Degrees that read back (times pi/180) to exactly `angle_rad` when such a double exists nearby.
double degrees_for_exact_radians(double angle_rad);
double radians_from_degrees(double angle_deg);
/// Times as written: rounded to the nanosecond, so 41 * 0.02 s reads 0.82.
Eigen::VectorXd rounded_times(const Eigen::VectorXd& time_s);
/// degrees_for_exact_radians() of every element.
Eigen::VectorXd degrees_of(const Eigen::VectorXd& angle_rad);

}  // namespace bellows
