// A long computation (identification, convergence prediction) takes a stop flag and looks at it
// between bounded steps, so SIGINT and SIGTERM are honoured inside it, not only between trials.
// The app sets the flag from its signal handler (app/signals); the engine knows no signals.
#pragma once

#include <atomic>
#include <stdexcept>

namespace bellows {

/// Null: the computation cannot be stopped.
using StopFlag = const std::atomic<bool>*;

inline bool stop_is_requested(StopFlag stop) { return stop != nullptr && stop->load(std::memory_order_relaxed); }

/// Thrown by a computation that stopped because its stop flag was set; anything it drove is vented
/// first. The app exits with 128 + the signal.
class Cancelled : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace bellows
