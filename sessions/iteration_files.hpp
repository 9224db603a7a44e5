// The CSV files of a session: a trajectory (time_s, angle_deg; or time_s, q1_deg, ... for several
// joints), an iteration's ILC-rate samples with the correction learned from it, and its tick-rate
// telemetry. Their columns are described once in sessions/record_columns.hpp (and listed in
// docs/session-format.md). Angles are stored in degrees, written so that they read back to the
// very same radians wherever such a decimal exists (always for trajectories built from degrees).
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "engine/trial/trajectory.hpp"
#include "sessions/session.hpp"

namespace bellows {

/// The headers of one-joint files (record_columns.hpp has every joint count's).
const std::vector<std::string_view>& trajectory_columns();
const std::vector<std::string_view>& samples_columns();
const std::vector<std::string_view>& telemetry_columns();

/// One column per joint of the trajectory (record_columns.hpp, trajectory_header()).
std::string format_trajectory_csv(const Trajectory& trajectory);
/// Checks the header for `joints` joints, the row count (N + 1), the uniform sampling at
/// `sample_time_s` and the joint limits.
Trajectory parse_trajectory_csv_file(std::string_view text, const std::string& source, const std::string& name,
                                     int learning_samples, double sample_time_s, const TrajectoryLimits& limits,
                                     int joints = 1);

/// Every joint's ILC-rate samples and the next correction (N x J, a VectorXd for one joint; 0 in
/// the last row).
std::string format_samples_csv(const TrialRecord& record, const Eigen::MatrixXd& next_corrections_bar);
/// Every joint's tick-rate telemetry.
std::string format_telemetry_csv(const TrialRecord& record);

/// Fills `data` (record samples of `joints` joints, next corrections); checks the header, N + 1
/// rows and the time column.
void parse_samples_csv(std::string_view text, const std::string& source, int learning_samples, double sample_time_s,
                       IterationData& data, int joints = 1);
/// Fills `data.record`'s ticks of the joints its samples have (parse_samples_csv first); checks
/// N * ticks_per_sample rows and the time column. A record with no joints is the caller's mistake
/// (std::logic_error), never an out-of-bounds read.
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
