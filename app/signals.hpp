// SIGINT and SIGTERM set a flag that the operator side polls: the engine then vents and the program
// exits cleanly. Install before starting any thread, so that threads inherit the mask choices.
#pragma once

#include <atomic>

namespace bellows {

void install_stop_signal_handlers();
/// Set once SIGINT or SIGTERM arrived.
const std::atomic<bool>& stop_requested();
/// The signal that arrived (0 if none), for the exit status 128 + signal.
int stop_signal();

}  // namespace bellows
