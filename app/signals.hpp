// SIGINT, SIGTERM, SIGHUP (the terminal closed, an ssh session dropped) and SIGQUIT (Ctrl-\) stop the program the
// same way: the handler latches the engine's emergency stop at once (the next tick vents, whatever
// the command queue holds) and sets a flag that the operator side polls to save, report and exit
// with 128 + signal. Install before starting any thread, so that threads inherit the mask choices.
#pragma once

#include <atomic>

namespace bellows {

class EngineCore;

void install_stop_signal_handlers();
/// For the commands that drive a device, from now on:
/// - SIGPIPE (the reader of standard output went away: `bellows run | tee log` with the tee ended) is
///   a stop signal too: its default would end the process at once, the valves as they were and the
///   last save not made. The status is then 4 (standard output could not be written). The other
///   commands keep the default and end quietly, as any tool piped into `head` does.
/// - SIGTSTP (Ctrl-Z) is ignored, as the console ignores it: a suspended process can neither vent
///   nor hold its tick, and the valves would stay as they were until it is continued.
void guard_device_command_signals();
/// Set once SIGINT, SIGTERM, SIGHUP or SIGQUIT arrived.
const std::atomic<bool>& stop_requested();
/// The signal that arrived (0 if none), for the exit status 128 + signal.
int stop_signal();
/// "SIGINT", "SIGTERM", "SIGHUP", "SIGQUIT", "SIGPIPE" (or "a signal").
const char* stop_signal_name();

/// While alive, a stop signal latches `core`'s emergency stop from the handler itself.
class StopSignalTarget {
 public:
  explicit StopSignalTarget(EngineCore& core);
  ~StopSignalTarget();
  StopSignalTarget(const StopSignalTarget&) = delete;
  StopSignalTarget& operator=(const StopSignalTarget&) = delete;
};

}  // namespace bellows
