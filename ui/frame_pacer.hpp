// When the UI thread redraws: at most 30 times a second, when something changed or trials run,
// and 10 times a second when only the live values move. Pure logic on a given clock, so that the
// limit is tested without a terminal.
#pragma once

#include <cstdint>

namespace bellows::ui {

class FramePacer {
 public:
  static constexpr double kFramePeriodS = 1.0 / 30.0;  // the most the screen is redrawn
  static constexpr double kIdleFramePeriodS = 0.1;     // live values only

  /// Whether to draw now; `revision` changes with every discrete change, `active` while trials
  /// run (the screen moves continuously). Records the frame when it says yes.
  bool should_draw(double now_s, std::uint64_t revision, bool active) {
    const double since = now_s - last_draw_s_;
    const bool changed = revision != drawn_revision_;
    const double period = active ? kFramePeriodS : kIdleFramePeriodS;
    if (!first_drawn_ || (since >= kFramePeriodS && (changed || since >= period))) {
      first_drawn_ = true;
      last_draw_s_ = now_s;
      drawn_revision_ = revision;
      return true;
    }
    return false;
  }

 private:
  bool first_drawn_ = false;
  double last_draw_s_ = 0.0;
  std::uint64_t drawn_revision_ = 0;
};

}  // namespace bellows::ui
