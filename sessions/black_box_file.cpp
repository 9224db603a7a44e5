#include "sessions/black_box_file.hpp"

#include <cmath>
#include <algorithm>
#include <functional>
#include <limits>
#include <stdexcept>

#include "engine/rt/engine_state.hpp"
#include "engine/base/errors.hpp"
#include "engine/control/safety.hpp"
#include "sessions/csv_table.hpp"
#include "sessions/iteration_files.hpp"
#include "sessions/record_columns.hpp"

namespace bellows {
namespace {

constexpr int kLastState = static_cast<int>(EngineState::kFault);
constexpr int kLastFault = static_cast<int>(kLastFaultCode);
// Legacy files store these codes (docs/session-format.md): they must keep their meaning.
static_assert(static_cast<int>(EngineState::kSafe) == 0 && kLastState == 3);
static_assert(static_cast<int>(FaultCode::kNone) == 0 && static_cast<int>(FaultCode::kSupplyLow) == 4 &&
              static_cast<int>(FaultCode::kSensorStale) == 7 && static_cast<int>(FaultCode::kHeartbeatLost) == 9 &&
              kLastFault == 16);

std::string state_name(int code) { return to_string(static_cast<EngineState>(code)); }
std::string fault_name_of(int code) { return fault_name(static_cast<FaultCode>(code)); }

// A whole number within [low, high] read back from `column`; NaN and fractions fail.
double whole_at(const Eigen::VectorXd& column, Eigen::Index row, double low, double high, const std::string& source,
                const char* name) {
  const double value = column(row);
  if (!(value == std::floor(value) && value >= low && value <= high)) {
    throw InputError(source + ": line " + std::to_string(row + 2) + ": " + name + " = " + std::to_string(value) +
                     " is not a whole number from " + std::to_string(static_cast<long long>(low)) + " to " +
                     std::to_string(static_cast<long long>(high)));
  }
  return value;
}

/// `text` with the state and fault fields of every row after the header replaced by `replace`
/// (column, field, line number). Rows too short to have them are left for parse_csv to refuse.
std::string with_named_fields_replaced(
    std::string_view text, const std::function<std::string(std::size_t, std::string_view, std::size_t)>& replace) {
  std::string out;
  out.reserve(text.size() + text.size() / 8);
  std::size_t line_number = 1;
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t end = text.find('\n', start);
    const bool has_end = end != std::string_view::npos;
    if (!has_end) end = text.size();
    const std::string_view line = text.substr(start, end - start);
    if (line_number == 1) {
      out += line;
    } else {
      std::size_t column = 0, field_start = 0;
      while (true) {
        const std::size_t comma = line.find(',', field_start);
        const std::string_view field =
            line.substr(field_start, comma == std::string_view::npos ? std::string_view::npos : comma - field_start);
        if (column > 0) out += ',';
        const bool named = column == kBlackBoxStateColumn || column == kBlackBoxFaultColumn;
        out += named ? replace(column, field, line_number) : std::string(field);
        if (comma == std::string_view::npos) break;
        field_start = comma + 1;
        ++column;
      }
    }
    if (has_end) out += '\n';
    start = end + 1;
    ++line_number;
  }
  return out;
}

/// The code of `name` among the names of codes 0..last, or an InputError.
int code_of(std::string_view name, int last, std::string (*name_of)(int), const std::string& source, std::size_t line,
            const char* what) {
  std::string known;
  for (int code = 0; code <= last; ++code) {
    if (name == name_of(code)) return code;
    if (code > 0) known += ", ";
    known += name_of(code);
  }
  std::string shown(name.substr(0, 40));
  for (char& c : shown) {
    if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f) c = '?';
  }
  throw InputError(source + ": line " + std::to_string(line) + ": " + what + " '" + shown + "' is not one of " + known);
}

std::string joined_header(const std::vector<std::string_view>& names) {
  std::string out;
  for (std::string_view name : names) {
    if (!out.empty()) out += ',';
    out += name;
  }
  return out;
}

}  // namespace

const std::vector<std::string_view>& legacy_black_box_columns() {
  static const std::vector<std::string_view> columns = {"tick",
                                                        "time_s",
                                                        "sensor_time_s",
                                                        "state",
                                                        "fault",
                                                        "angle_deg",
                                                        "desired_deg",
                                                        "pressure_a_bar",
                                                        "pressure_b_bar",
                                                        "supply_bar",
                                                        "u_total_bar",
                                                        "pressure_a_setpoint_bar",
                                                        "pressure_b_setpoint_bar",
                                                        "inlet_a_duty",
                                                        "outlet_a_duty",
                                                        "inlet_b_duty",
                                                        "outlet_b_duty",
                                                        "sample",
                                                        "trial_id"};
  return columns;
}

int black_box_joints(const std::vector<TickRecord>& ticks) {
  int joints = 1;
  for (const TickRecord& t : ticks) joints = std::max(joints, std::min(t.reading.joint_count, kMaxJoints));
  return joints;
}

std::vector<Eigen::VectorXd> black_box_values(const std::vector<TickRecord>& ticks) {
  return black_box_file_values(ticks, black_box_joints(ticks));
}

std::string format_black_box_csv(const std::vector<TickRecord>& ticks) {
  if (ticks.empty()) throw std::invalid_argument("format_black_box_csv: no ticks");
  const std::vector<Eigen::VectorXd> c = black_box_values(ticks);
  const std::vector<std::string> header = black_box_header(black_box_joints(ticks));
  std::vector<CsvColumn> columns;
  for (std::size_t i = 0; i < c.size(); ++i) columns.push_back({header[i], &c[i]});
  std::string numeric;
  append_csv(numeric, columns);
  return with_named_fields_replaced(numeric, [](std::size_t column, std::string_view field, std::size_t) {
    const int code = std::stoi(std::string(field));
    return column == kBlackBoxStateColumn ? state_name(code) : fault_name_of(code);
  });
}

std::vector<TickRecord> parse_black_box_csv(std::string_view text, const std::string& source, int expected_ticks) {
  std::string_view header = text.substr(0, text.find('\n'));
  while (!header.empty() && (header.back() == '\r' || header.back() == ' ' || header.back() == '\t'))
    header.remove_suffix(1);
  int joints = 0;  // from the header: the one of 1..kMaxJoints joints it is
  for (int j = 1; j <= kMaxJoints && joints == 0; ++j) {
    if (header == joined_header(header_views(black_box_header(j)))) joints = j;
  }
  std::vector<Eigen::VectorXd> c;
  if (header == joined_header(legacy_black_box_columns())) {
    joints = 1;
    c = parse_csv(text, legacy_black_box_columns(), source, NonFinite::kAccept);
  } else if (joints == 0) {
    // Refuses the header, naming the one-joint one.
    c = parse_csv(text, header_views(black_box_header(1)), source, NonFinite::kAccept);
  } else {
    // Names back to codes, then the strict numeric reader checks everything else.
    const std::string numeric =
        with_named_fields_replaced(text, [&](std::size_t column, std::string_view field, std::size_t line) {
          return column == kBlackBoxStateColumn
                     ? std::to_string(code_of(field, kLastState, state_name, source, line, "state"))
                     : std::to_string(code_of(field, kLastFault, fault_name_of, source, line, "fault"));
        });
    c = parse_csv(numeric, header_views(black_box_header(joints)), source, NonFinite::kAccept);
  }
  if (c[0].size() != expected_ticks) {
    throw InputError(source + ": expected " + std::to_string(expected_ticks) +
                     " rows (the ticks the manifest lists), found " + std::to_string(c[0].size()));
  }
  // The whole-number columns (joint 1's block: the same positions in every header) before any is cast.
  const std::vector<TickColumn>& table = black_box_record_columns();
  const auto column = [&](std::string_view name) -> const Eigen::VectorXd& {
    const auto found = std::find_if(table.begin(), table.end(), [&](const TickColumn& t) { return t.name == name; });
    return c[static_cast<std::size_t>(found - table.begin())];
  };
  constexpr double kMostTicks = 9007199254740992.0;  // 2^53: every tick count a double holds exactly
  for (Eigen::Index k = 0; k < c[0].size(); ++k) {
    const double tick = whole_at(column("tick"), k, 0.0, kMostTicks, source, "tick");
    if (k > 0 && tick <= column("tick")(k - 1)) {
      throw InputError(source + ": line " + std::to_string(k + 2) + ": tick " +
                       std::to_string(static_cast<std::uint64_t>(tick)) + " does not follow tick " +
                       std::to_string(static_cast<std::uint64_t>(column("tick")(k - 1))) +
                       " (ticks increase row by row)");
    }
    whole_at(column("state"), k, 0, kLastState, source, "state");
    whole_at(column("fault"), k, 0, kLastFault, source, "fault");
    whole_at(column("sample"), k, -1, std::numeric_limits<int>::max(), source, "sample");
    whole_at(column("trial_id"), k, 0, std::numeric_limits<std::uint32_t>::max(), source, "trial_id");
  }
  return black_box_from_file_values(c, joints);
}

}  // namespace bellows
