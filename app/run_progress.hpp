// What `bellows run` tells the operator while it runs: one line per iteration when its output is a
// file or a pipe (or with --verbose), a single line redrawn in place on a terminal (iteration, RMS,
// ETA) so that a run of hundreds of iterations does not scroll them away, nothing but errors with
// --quiet (the JSON report is not progress: --json still prints it).
#pragma once

#include <chrono>
#include <iosfwd>
#include <string>

#include "engine/operator/learning_session.hpp"

namespace bellows {

enum class ProgressStyle { kLines, kRedrawn, kQuiet };

/// --quiet wins, then --verbose (lines); otherwise a terminal gets the redrawn line.
ProgressStyle choose_progress_style(bool verbose, bool quiet, bool terminal);

class RunProgressReport {
 public:
  /// `first_iteration`..`last_iteration` are the iterations this run will run (docs/iterations.md).
  RunProgressReport(std::ostream& out, ProgressStyle style, int first_iteration, int last_iteration);
  RunProgressReport(const RunProgressReport&) = delete;
  RunProgressReport& operator=(const RunProgressReport&) = delete;

  /// Something worth knowing that is not an error (the session's directory, a warning): not with --quiet.
  void note(const std::string& line);
  /// An error or a loss: always, on its own line.
  void error(const std::string& line);
  /// The first trial starts now: the ETA counts from here, not from the setup before it.
  void begin_trials() { started_ = std::chrono::steady_clock::now(); }
  /// A completed iteration.
  void iteration(const IterationSummary& summary);
  /// Ends the redrawn line (it stays on screen as the run's last word on progress).
  void finish();

 private:
  void end_redrawn_line();

  std::ostream& out_;
  ProgressStyle style_;
  int first_iteration_;
  int last_iteration_;
  bool line_open_ = false;  // a redrawn line is on screen without its newline
  std::chrono::steady_clock::time_point started_ = std::chrono::steady_clock::now();
};

}  // namespace bellows
