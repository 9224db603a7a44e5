#include "app/run_progress.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ostream>

namespace bellows {
namespace {

/// "  joints 9.608 / 15.038": each joint's RMS after the overall one; nothing for one joint.
std::string joints_text(const IterationSummary& s) {
  if (s.joint_rms_deg.size() < 2) return "";
  std::string text = "  joints";
  char value[32];
  for (Eigen::Index j = 0; j < s.joint_rms_deg.size(); ++j) {
    std::snprintf(value, sizeof value, "%s%.3f", j == 0 ? " " : " / ", s.joint_rms_deg(j));
    text += value;
  }
  return text;
}

std::string per_iteration_line(const IterationSummary& s) {
  char line[160];
  std::snprintf(line, sizeof line, "iteration %3d  rms %7.3f deg  max error %7.3f deg  max correction %6.4f bar",
                s.iteration, s.rms_deg, s.max_abs_error_deg, s.max_abs_correction_bar);
  return line + joints_text(s);
}

/// "0.4 s", "42 s", "3 min 05 s", "2 h 07 min": coarse enough to read at a glance.
std::string duration_text(double seconds) {
  const long total = std::lround(std::max(0.0, seconds));
  char text[32];
  if (seconds < 9.95) std::snprintf(text, sizeof text, "%.1f s", std::max(0.0, seconds));
  else if (total < 60) std::snprintf(text, sizeof text, "%ld s", total);
  else if (total < 3600) std::snprintf(text, sizeof text, "%ld min %02ld s", total / 60, total % 60);
  else std::snprintf(text, sizeof text, "%ld h %02ld min", total / 3600, (total % 3600) / 60);
  return text;
}

}  // namespace

ProgressStyle choose_progress_style(bool verbose, bool quiet, bool terminal) {
  if (quiet) return ProgressStyle::kQuiet;
  if (verbose || !terminal) return ProgressStyle::kLines;
  return ProgressStyle::kRedrawn;
}

RunProgressReport::RunProgressReport(std::ostream& out, ProgressStyle style, int first_iteration, int last_iteration)
    : out_(out), style_(style), first_iteration_(first_iteration), last_iteration_(last_iteration) {}

void RunProgressReport::note(const std::string& line) {
  if (style_ == ProgressStyle::kQuiet) return;
  end_redrawn_line();
  out_ << line << std::endl;
}

void RunProgressReport::error(const std::string& line) {
  end_redrawn_line();
  out_ << line << std::endl;
}

void RunProgressReport::iteration(const IterationSummary& s) {
  if (style_ == ProgressStyle::kQuiet) return;
  if (style_ == ProgressStyle::kLines) {
    out_ << per_iteration_line(s) << std::endl;
    return;
  }
  // Redrawn: carriage return, the line, erase what a longer previous line left (ECMA-48 EL).
  const double elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count();
  const int done = s.iteration - first_iteration_ + 1;
  const int left = last_iteration_ - s.iteration;
  char line[160];
  std::snprintf(line, sizeof line, "iteration %d of %d..%d  rms %.3f deg%s  %s", s.iteration, first_iteration_,
                last_iteration_, s.rms_deg, joints_text(s).c_str(),
                left > 0 ? ("ETA " + duration_text(elapsed_s / std::max(done, 1) * left)).c_str()
                         : ("done in " + duration_text(elapsed_s)).c_str());
  out_ << '\r' << line << "\x1b[K" << std::flush;
  line_open_ = true;
}

void RunProgressReport::finish() { end_redrawn_line(); }

void RunProgressReport::end_redrawn_line() {
  if (!line_open_) return;
  out_ << std::endl;
  line_open_ = false;
}

}  // namespace bellows
