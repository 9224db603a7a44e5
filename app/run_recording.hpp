// The session side of `bellows run`: a new session saved as the run goes (unless --no-save), or a
// saved session continued with --resume. Each completed iteration is on disk before its progress
// line is printed; faults are recorded as events before the run gives up.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include "app/run_command.hpp"
#include "devices/simulated_arm.hpp"
#include "engine/control_core.hpp"
#include "engine/learning_session.hpp"
#include "sessions/session_writer.hpp"

namespace bellows {

class RunRecording {
 public:
  /// With --resume: takes the session's lock and loads it (InputError if busy or bad).
  explicit RunRecording(const RunOptions& options);

  bool resuming() const { return resuming_; }
  /// The session being continued (valid when resuming()).
  const Session& resumed() const { return resumed_; }
  /// The simulated arm's seed the resumed session was started with.
  std::uint64_t resumed_seed() const;
  /// Trials to run for `--iterations K`: K + 1 from scratch (trial 0 is feedback only), K when
  /// continuing after completed iterations.
  int trials(int iterations) const;

  /// A fresh run: creates the session (nothing with --no-save).
  void start(const Configuration& config, const Trajectory& trajectory, const std::string& device, std::uint64_t seed,
             int iterations);
  /// A resumed run: puts the arm, the controllers and the learning where the session stopped,
  /// and records the resumption.
  void restore(SimulatedArm& arm, ControlCore& core, LearningSession& learning);
  /// After a trial and the learning from it.
  void save(const LearningSession& learning, const IterationSummary& summary, const SimulatedArm& arm,
            const ControlCore& core);
  /// Records a fault; never throws (the fault itself is what the caller reports).
  void fault(const std::string& what) noexcept;
  void finish(int trials_run);

  /// The session directory; empty with --no-save.
  std::filesystem::path directory() const;

 private:
  void restore_completed(SimulatedArm& arm, ControlCore& core, LearningSession& learning) const;

  const RunOptions& options_;
  bool resuming_ = false;
  Session resumed_;
  std::optional<SessionWriter> writer_;
};

}  // namespace bellows
