#include "sessions/record_columns.hpp"

#include <utility>

#include "engine/base/units.hpp"
#include "sessions/iteration_files.hpp"

namespace bellows {
namespace {

using S = TrialSamples;
using T = TrialTicks;
constexpr ColumnScale kAsIs = ColumnScale::kAsIs, kDegrees = ColumnScale::kDegrees, kTime = ColumnScale::kTime;
constexpr ColumnScope kJoint = ColumnScope::kPerJoint, kShared = ColumnScope::kShared;

std::size_t at(int joint) { return static_cast<std::size_t>(joint); }

Eigen::VectorXd written(const Eigen::VectorXd& values, ColumnScale scale) {
  switch (scale) {
    case ColumnScale::kDegrees:
      return degrees_of(values);
    case ColumnScale::kTime:
      return rounded_times(values);
    case ColumnScale::kAsIs:
      break;
  }
  return values;
}

Eigen::VectorXd read_back(Eigen::VectorXd&& values, ColumnScale scale) {
  if (scale == ColumnScale::kDegrees) return values * kRadPerDeg;  // the engine's own conversion
  return std::move(values);
}

template <typename Column>
std::vector<std::string> header_of(const std::vector<Column>& table, int joints) {
  std::vector<std::string> names;
  for (int joint = 0; joint < joints; ++joint) {
    for (const Column& column : table) {
      if (joint == 0 || column.scope == ColumnScope::kPerJoint) names.push_back(joint_column_name(column.name, joint));
    }
  }
  return names;
}

}  // namespace

const std::vector<RecordColumn<TrialSamples>>& samples_record_columns() {
  static const std::vector<RecordColumn<TrialSamples>> columns = {
      {"time_s", "s", "k T", kTime, kShared, nullptr, &TrialRecord::sample_time_s},
      {"angle_setpoint_deg", "deg", "desired angle yD(k)", kDegrees, kJoint, &S::setpoint_rad, nullptr},
      {"angle_deg", "deg", "measured angle", kDegrees, kJoint, &S::angle_rad, nullptr},
      {"error_deg", "deg", "yD(k) - y(k); 0 at k = 0", kDegrees, kJoint, &S::error_rad, nullptr},
      {"u_pid_bar", "bar", "PID + feed-forward output", kAsIs, kJoint, &S::u_pid_bar, nullptr},
      {"u_ilc_bar", "bar", "learned correction applied at sample k (0 at k = N)", kAsIs, kJoint, &S::u_ilc_bar,
       nullptr},
      {"u_tot_bar", "bar", "u_pid + u_ilc, before the set-point clamp", kAsIs, kJoint, &S::u_total_bar, nullptr},
      {"pressure_a_bar", "bar (abs)", "measured pressure in actuator A", kAsIs, kJoint, &S::pressure_a_bar, nullptr},
      {"pressure_b_bar", "bar (abs)", "measured pressure in actuator B", kAsIs, kJoint, &S::pressure_b_bar, nullptr},
      {"pressure_a_setpoint_bar", "bar (abs)", "set point of A", kAsIs, kJoint, &S::setpoint_a_bar, nullptr},
      {"pressure_b_setpoint_bar", "bar (abs)", "set point of B", kAsIs, kJoint, &S::setpoint_b_bar, nullptr},
      {"u_ilc_next_bar", "bar", "correction learned from this iteration, applied in the next (0 at k = N)", kAsIs,
       kJoint, nullptr, nullptr},
  };
  return columns;
}

const std::vector<RecordColumn<TrialTicks>>& telemetry_record_columns() {
  static const std::vector<RecordColumn<TrialTicks>> columns = {
      {"time_s", "s", "i tick_s", kTime, kShared, nullptr, &TrialRecord::tick_time_s},
      {"angle_deg", "deg", "measured angle", kDegrees, kJoint, &T::angle_rad, nullptr},
      {"pressure_a_bar", "bar (abs)", "measured pressure in actuator A", kAsIs, kJoint, &T::pressure_a_bar, nullptr},
      {"pressure_b_bar", "bar (abs)", "measured pressure in actuator B", kAsIs, kJoint, &T::pressure_b_bar, nullptr},
      {"supply_bar", "bar (abs)", "measured supply pressure", kAsIs, kShared, nullptr, &TrialRecord::supply_bar},
      {"pressure_a_setpoint_bar", "bar (abs)", "set point of A in force", kAsIs, kJoint, &T::setpoint_a_bar, nullptr},
      {"pressure_b_setpoint_bar", "bar (abs)", "set point of B in force", kAsIs, kJoint, &T::setpoint_b_bar, nullptr},
      {"inlet_a_duty", "0..1", "inlet valve A's PWM duty cycle", kAsIs, kJoint, &T::inlet_a, nullptr},
      {"outlet_a_duty", "0..1", "outlet valve A's PWM duty cycle", kAsIs, kJoint, &T::outlet_a, nullptr},
      {"inlet_b_duty", "0..1", "inlet valve B's PWM duty cycle", kAsIs, kJoint, &T::inlet_b, nullptr},
      {"outlet_b_duty", "0..1", "outlet valve B's PWM duty cycle", kAsIs, kJoint, &T::outlet_b, nullptr},
  };
  return columns;
}

const std::vector<TickColumn>& black_box_record_columns() {
  using Tick = TickRecord;
  static const std::vector<TickColumn> columns = {
      {"tick", "", "the engine's tick count", kAsIs, kShared,
       [](const Tick& t, int) { return static_cast<double>(t.tick); },
       [](Tick& t, int, double v) { t.tick = static_cast<std::uint64_t>(v); }},
      {"time_s", "s", "engine time of the tick", kAsIs, kShared, [](const Tick& t, int) { return t.time_s; },
       [](Tick& t, int, double v) { t.time_s = v; }},
      {"sensor_time_s", "s", "time of the reading the tick used", kAsIs, kShared,
       [](const Tick& t, int) { return t.reading.time_s; }, [](Tick& t, int, double v) { t.reading.time_s = v; }},
      {"state", "", "engine state (SAFE, ARMED, RUNNING, FAULT)", kAsIs, kShared,
       [](const Tick& t, int) { return static_cast<double>(t.state); },
       [](Tick& t, int, double v) { t.state = static_cast<EngineState>(v); }},
      {"fault", "", "the latched fault (none, angle-limit, ...)", kAsIs, kShared,
       [](const Tick& t, int) { return static_cast<double>(t.fault); },
       [](Tick& t, int, double v) { t.fault = static_cast<FaultCode>(v); }},
      {"angle_deg", "deg", "measured angle", kDegrees, kJoint,
       [](const Tick& t, int j) { return t.reading.joint[at(j)].angle_rad; },
       [](Tick& t, int j, double v) { t.reading.joint[at(j)].angle_rad = v; }},
      {"angle_setpoint_deg", "deg", "desired angle", kDegrees, kJoint,
       [](const Tick& t, int j) { return t.joint(j).desired_rad; },
       [](Tick& t, int j, double v) { t.joint(j).desired_rad = v; }},
      {"pressure_a_bar", "bar (abs)", "measured pressure in actuator A", kAsIs, kJoint,
       [](const Tick& t, int j) { return t.reading.joint[at(j)].chamber_bar[0]; },
       [](Tick& t, int j, double v) { t.reading.joint[at(j)].chamber_bar[0] = v; }},
      {"pressure_b_bar", "bar (abs)", "measured pressure in actuator B", kAsIs, kJoint,
       [](const Tick& t, int j) { return t.reading.joint[at(j)].chamber_bar[1]; },
       [](Tick& t, int j, double v) { t.reading.joint[at(j)].chamber_bar[1] = v; }},
      {"supply_bar", "bar (abs)", "measured supply pressure", kAsIs, kShared,
       [](const Tick& t, int) { return t.reading.supply_bar; },
       [](Tick& t, int, double v) { t.reading.supply_bar = v; }},
      {"u_tot_bar", "bar", "u_pid + u_ilc, before the set-point clamp", kAsIs, kJoint,
       [](const Tick& t, int j) { return t.joint(j).u_total_bar; },
       [](Tick& t, int j, double v) { t.joint(j).u_total_bar = v; }},
      {"pressure_a_setpoint_bar", "bar (abs)", "set point of A", kAsIs, kJoint,
       [](const Tick& t, int j) { return t.joint(j).setpoints.a_bar; },
       [](Tick& t, int j, double v) { t.joint(j).setpoints.a_bar = v; }},
      {"pressure_b_setpoint_bar", "bar (abs)", "set point of B", kAsIs, kJoint,
       [](const Tick& t, int j) { return t.joint(j).setpoints.b_bar; },
       [](Tick& t, int j, double v) { t.joint(j).setpoints.b_bar = v; }},
      {"inlet_a_duty", "0..1", "inlet valve A's PWM duty cycle", kAsIs, kJoint,
       [](const Tick& t, int j) { return t.valves.joint[at(j)].inlet_duty[0]; },
       [](Tick& t, int j, double v) { t.valves.joint[at(j)].inlet_duty[0] = v; }},
      {"outlet_a_duty", "0..1", "outlet valve A's PWM duty cycle", kAsIs, kJoint,
       [](const Tick& t, int j) { return t.valves.joint[at(j)].outlet_duty[0]; },
       [](Tick& t, int j, double v) { t.valves.joint[at(j)].outlet_duty[0] = v; }},
      {"inlet_b_duty", "0..1", "inlet valve B's PWM duty cycle", kAsIs, kJoint,
       [](const Tick& t, int j) { return t.valves.joint[at(j)].inlet_duty[1]; },
       [](Tick& t, int j, double v) { t.valves.joint[at(j)].inlet_duty[1] = v; }},
      {"outlet_b_duty", "0..1", "outlet valve B's PWM duty cycle", kAsIs, kJoint,
       [](const Tick& t, int j) { return t.valves.joint[at(j)].outlet_duty[1]; },
       [](Tick& t, int j, double v) { t.valves.joint[at(j)].outlet_duty[1] = v; }},
      {"sample", "", "ILC sample of the running trial, -1 when none runs", kAsIs, kShared,
       [](const Tick& t, int) { return static_cast<double>(t.sample); },
       [](Tick& t, int, double v) { t.sample = static_cast<int>(v); }},
      {"trial_id", "", "the running trial's id", kAsIs, kShared,
       [](const Tick& t, int) { return static_cast<double>(t.trial_id); },
       [](Tick& t, int, double v) { t.trial_id = static_cast<std::uint32_t>(v); }},
  };
  return columns;
}

std::string joint_column_name(std::string_view name, int joint) {
  std::string out(name);
  if (joint > 0)
    out.append("_j").append(
        std::to_string(joint + 1));  // by appends: GCC 12 warns falsely (-Wrestrict) on "_j" + string
  return out;
}

std::vector<std::string> samples_header(int joints) { return header_of(samples_record_columns(), joints); }
std::vector<std::string> telemetry_header(int joints) { return header_of(telemetry_record_columns(), joints); }
std::vector<std::string> black_box_header(int joints) { return header_of(black_box_record_columns(), joints); }

std::vector<std::string> trajectory_header(int joints) {
  if (joints == 1) return {"time_s", "angle_deg"};
  std::vector<std::string> names = {"time_s"};
  for (int joint = 1; joint <= joints; ++joint)
    names.push_back(std::string("q").append(std::to_string(joint)).append("_deg"));
  return names;
}

std::vector<std::string_view> header_views(const std::vector<std::string>& names) {
  return {names.begin(), names.end()};
}

std::vector<Eigen::VectorXd> samples_file_values(const TrialRecord& record,
                                                 const Eigen::MatrixXd& next_corrections_bar) {
  std::vector<Eigen::VectorXd> values;
  for (int joint = 0; joint < record.joint_count(); ++joint) {
    const TrialSamples& samples = record.joint_samples(joint);
    for (const RecordColumn<TrialSamples>& column : samples_record_columns()) {
      if (column.scope == ColumnScope::kShared) {
        if (joint == 0) values.push_back(written(record.*column.shared, column.scale));
        continue;
      }
      if (column.member != nullptr) {
        values.push_back(written(samples.*column.member, column.scale));
        continue;
      }
      Eigen::VectorXd next = Eigen::VectorXd::Zero(record.sample_time_s.size());
      const Eigen::Index learned = std::min(next.size(), next_corrections_bar.rows());
      if (joint < next_corrections_bar.cols()) next.head(learned) = next_corrections_bar.col(joint).head(learned);
      values.push_back(std::move(next));
    }
  }
  return values;
}

std::vector<Eigen::VectorXd> telemetry_file_values(const TrialRecord& record) {
  std::vector<Eigen::VectorXd> values;
  for (int joint = 0; joint < record.joint_count(); ++joint) {
    for (const RecordColumn<TrialTicks>& column : telemetry_record_columns()) {
      if (column.scope == ColumnScope::kShared) {
        if (joint == 0) values.push_back(written(record.*column.shared, column.scale));
        continue;
      }
      values.push_back(written(record.joint_ticks(joint).*column.member, column.scale));
    }
  }
  return values;
}

std::vector<Eigen::VectorXd> black_box_file_values(const std::vector<TickRecord>& ticks, int joints) {
  const auto rows = static_cast<Eigen::Index>(ticks.size());
  std::vector<Eigen::VectorXd> values;
  for (int joint = 0; joint < joints; ++joint) {
    for (const TickColumn& column : black_box_record_columns()) {
      if (joint > 0 && column.scope == ColumnScope::kShared) continue;
      Eigen::VectorXd v(rows);
      for (Eigen::Index k = 0; k < rows; ++k) {
        const double value = column.value(ticks[static_cast<std::size_t>(k)], joint);
        v(k) = column.scale == ColumnScale::kDegrees ? degrees_for_exact_radians(value) : value;
      }
      values.push_back(std::move(v));
    }
  }
  return values;
}

std::vector<Eigen::VectorXd> trajectory_file_values(const Trajectory& trajectory) {
  const Eigen::Index rows = trajectory.learning_samples() + 1;
  Eigen::VectorXd times(rows);
  for (Eigen::Index k = 0; k < rows; ++k) times(k) = static_cast<double>(k) * trajectory.sample_time_s;
  std::vector<Eigen::VectorXd> values = {rounded_times(times)};
  for (int joint = 0; joint < trajectory.joints(); ++joint) values.push_back(degrees_of(trajectory.joint(joint)));
  return values;
}

Eigen::MatrixXd samples_from_file_values(std::vector<Eigen::VectorXd>& columns, int joints, TrialRecord& record) {
  record.joints.resize(static_cast<std::size_t>(joints));
  const Eigen::Index rows = columns.empty() ? 0 : columns.front().size();
  Eigen::MatrixXd next(rows, joints);
  std::size_t at = 0;
  for (int joint = 0; joint < joints; ++joint) {
    TrialSamples& samples = record.joint_samples(joint);
    for (const RecordColumn<TrialSamples>& column : samples_record_columns()) {
      if (column.scope == ColumnScope::kShared) {
        if (joint == 0) record.*column.shared = read_back(std::move(columns[at++]), column.scale);
        continue;
      }
      Eigen::VectorXd& values = columns[at++];
      if (column.member == nullptr) next.col(joint) = values;
      else samples.*column.member = read_back(std::move(values), column.scale);
    }
  }
  return next;
}

void telemetry_from_file_values(std::vector<Eigen::VectorXd>& columns, TrialRecord& record) {
  std::size_t at = 0;
  for (int joint = 0; joint < record.joint_count(); ++joint) {
    TrialTicks& ticks = record.joint_ticks(joint);
    for (const RecordColumn<TrialTicks>& column : telemetry_record_columns()) {
      if (column.scope == ColumnScope::kShared) {
        if (joint == 0) record.*column.shared = read_back(std::move(columns[at++]), column.scale);
        continue;
      }
      ticks.*column.member = read_back(std::move(columns[at++]), column.scale);
    }
  }
}

std::vector<TickRecord> black_box_from_file_values(const std::vector<Eigen::VectorXd>& columns, int joints) {
  const Eigen::Index rows = columns.empty() ? 0 : columns.front().size();
  std::vector<TickRecord> ticks(static_cast<std::size_t>(rows));
  for (TickRecord& tick : ticks) tick.reading.joint_count = tick.valves.joint_count = joints;
  std::size_t at = 0;
  for (int joint = 0; joint < joints; ++joint) {
    for (const TickColumn& column : black_box_record_columns()) {
      if (joint > 0 && column.scope == ColumnScope::kShared) continue;  // joint 1's, read first
      const Eigen::VectorXd& values = columns[at++];
      for (Eigen::Index k = 0; k < rows; ++k) {
        const double value = column.scale == ColumnScale::kDegrees ? radians_from_degrees(values(k)) : values(k);
        column.set(ticks[static_cast<std::size_t>(k)], joint, value);
      }
    }
  }
  return ticks;
}

}  // namespace bellows
