// A fault's black box as a session stores it: the engine's last ticks before and including the
// fault tick, one CSV row per tick (columns in docs/session-format.md). Its columns use the
// iteration files' names (`angle_setpoint_deg`, `u_tot_bar`) and its state and fault columns hold
// names (`RUNNING`, `overpressure`). Files written before that (`desired_deg`, `u_total_bar`,
// numeric codes) are still read.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Dense>

#include "engine/rt/engine_messages.hpp"

namespace bellows {

const std::vector<std::string_view>& black_box_columns();
/// The header of black boxes written before the columns had the iteration files' names.
const std::vector<std::string_view>& legacy_black_box_columns();
/// Positions of the two named columns in black_box_columns().
inline constexpr std::size_t kBlackBoxStateColumn = 3;
inline constexpr std::size_t kBlackBoxFaultColumn = 4;

/// One vector per column of black_box_columns(), one row per tick; the state and fault columns
/// hold the enums' codes (exporters turn them into names).
std::vector<Eigen::VectorXd> black_box_values(const std::vector<TickRecord>& ticks);

/// Throws std::invalid_argument when `ticks` is empty (a black box always holds the fault tick).
std::string format_black_box_csv(const std::vector<TickRecord>& ticks);

/// The ticks, oldest first; checks the header (current or legacy), `expected_ticks` rows,
/// increasing ticks and valid state and fault names (codes in a legacy file). Throws InputError
/// naming `source` and the line at fault.
std::vector<TickRecord> parse_black_box_csv(std::string_view text, const std::string& source, int expected_ticks);

}  // namespace bellows
