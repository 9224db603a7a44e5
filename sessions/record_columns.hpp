// The record types as files store them, described once: for every column of an iteration's samples
// (TrialSamples plus the correction learned), telemetry (TrialTicks) and a fault's black box (the
// engine's TickRecords) its name, unit, meaning,
// how its values are written (radians as degrees, times rounded to the nanosecond) and which member
// of the record holds it. The session's CSV writer and reader, the consistency checks and the
// CSV/JSON/MAT exports all take their columns from here (docs/session-format.md lists the same).
// It lives in sessions/, not engine/: it is about files.
//
// Several joints (issue 14): one file per iteration still, with one block of columns per joint.
// Joint 1's columns keep their names (a one-joint file is exactly what it always was); joint j > 1
// repeats the per-joint columns with the suffix `_j<j>` (`angle_deg_j2`) after joint 1's. Shared
// columns (time, supply) are written once, among joint 1's: the record keeps them once.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Dense>

#include "engine/rt/engine_messages.hpp"
#include "engine/trial/trajectory.hpp"
#include "engine/trial/trial_record.hpp"

namespace bellows {

/// How a column's values are written: as they are, radians as degrees (reading back bit for bit,
/// iteration_files.hpp), or times rounded to the nanosecond.
enum class ColumnScale { kAsIs, kDegrees, kTime };
/// A column per joint, or one for the whole record (the same values in every joint's record).
enum class ColumnScope { kPerJoint, kShared };

/// `Joint`: the per-joint part of the record (TrialSamples or TrialTicks).
template <typename Joint>
struct RecordColumn {
  std::string_view name;     // joint 1's; joint j > 1 adds "_j<j>"
  std::string_view unit;     // "s", "deg", "bar", "bar (abs)", "0..1"
  std::string_view meaning;  // one line for people (docs, exports)
  ColumnScale scale;
  ColumnScope scope;
  Eigen::VectorXd Joint::*member;        // where each joint keeps it (kPerJoint)
  Eigen::VectorXd TrialRecord::*shared;  // where the record keeps it (kShared)
  // Both null: the correction learned (samples).
};

/// An iteration's ILC-rate samples, N + 1 rows, in file order.
const std::vector<RecordColumn<TrialSamples>>& samples_record_columns();
/// An iteration's tick-rate telemetry, N x ticks_per_sample rows, in file order.
const std::vector<RecordColumn<TrialTicks>>& telemetry_record_columns();

/// A column of a fault's black box: one value per tick, read from and written into a TickRecord
/// (which keeps a joint's values in TickRecord::joints or in its reading or valves: hence functions).
struct TickColumn {
  std::string_view name;
  std::string_view unit;
  std::string_view meaning;
  ColumnScale scale;  // kDegrees for angles; never kTime (a black box keeps the engine's times as they are)
  ColumnScope scope;
  double (*value)(const TickRecord& tick, int joint);
  void (*set)(TickRecord& tick, int joint, double value);
};
/// A black box's ticks, one row per tick, in file order (docs/session-format.md).
const std::vector<TickColumn>& black_box_record_columns();

/// `name` of joint `joint` (0 = joint 1: the name itself; else name + "_j" + (joint + 1)).
std::string joint_column_name(std::string_view name, int joint);

/// The header of a file of `joints` joints: joint 1's columns (shared ones among them) in table
/// order, then each further joint's per-joint columns.
std::vector<std::string> samples_header(int joints);
std::vector<std::string> telemetry_header(int joints);
std::vector<std::string> black_box_header(int joints);
/// The trajectory file's header: `time_s,angle_deg` for one joint (as always), else
/// `time_s,q1_deg,...,qJ_deg` (the format `bellows run --trajectory FILE.csv` reads).
std::vector<std::string> trajectory_header(int joints);
/// Views of `names` for the CSV reader.
std::vector<std::string_view> header_views(const std::vector<std::string>& names);

/// Every column's values as written, in the order of samples_header(record.joint_count()).
/// `next_corrections_bar` is N x J (a missing row or column is 0); the last row's is 0.
std::vector<Eigen::VectorXd> samples_file_values(const TrialRecord& record,
                                                 const Eigen::MatrixXd& next_corrections_bar);
std::vector<Eigen::VectorXd> telemetry_file_values(const TrialRecord& record);
/// Every column of black_box_header(joints), one row per tick, angles in degrees as written.
std::vector<Eigen::VectorXd> black_box_file_values(const std::vector<TickRecord>& ticks, int joints);
std::vector<Eigen::VectorXd> trajectory_file_values(const Trajectory& trajectory);

/// The record's samples (prepared for `joints` joints) from the columns of samples_header(joints)
/// as read; returns the correction learned, (N + 1) x J as the file holds it.
Eigen::MatrixXd samples_from_file_values(std::vector<Eigen::VectorXd>& columns, int joints, TrialRecord& record);
/// The record's ticks from the columns of telemetry_header(record.joint_count()) as read.
void telemetry_from_file_values(std::vector<Eigen::VectorXd>& columns, TrialRecord& record);
/// Ticks (one per row) of `joints` joints from the columns of black_box_header(joints) as read.
std::vector<TickRecord> black_box_from_file_values(const std::vector<Eigen::VectorXd>& columns, int joints);

}  // namespace bellows
