// A fault's black box as a session stores it: the engine's last ticks before and including the
// fault tick, one CSV row per tick (columns and codes in docs/session-format.md).
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "engine/engine_messages.hpp"

namespace bellows {

const std::vector<std::string_view>& black_box_columns();

/// Throws std::invalid_argument when `ticks` is empty (a black box always holds the fault tick).
std::string format_black_box_csv(const std::vector<TickRecord>& ticks);

/// The ticks, oldest first; checks the header, `expected_ticks` rows, increasing ticks and valid
/// state and fault codes. Throws InputError naming `source` and the line at fault.
std::vector<TickRecord> parse_black_box_csv(std::string_view text, const std::string& source, int expected_ticks);

}  // namespace bellows
