// Typed errors carrying context (libfranka-style). The app maps each kind to one clear line on
// stderr and its own exit status (docs/architecture.md, "Exit statuses"):
//   InputError        2  bad input: a file, a config key, an option, a message
//   FaultError        3  the engine latched a fault (a guard or an emergency stop)
//   EnvironmentError  4  the environment refused: real-time scheduling, a bus, a rig or an
//                        address that cannot be opened, a disk that cannot be written
#pragma once

#include <stdexcept>
#include <string>

namespace bellows {

inline constexpr int kExitOk = 0;
inline constexpr int kExitBadInput = 2;
inline constexpr int kExitFault = 3;
inline constexpr int kExitEnvironment = 4;

/// Every error bellows raises on purpose; `exit_status()` is what the app exits with.
class BellowsError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
  virtual int exit_status() const noexcept = 0;
};

/// Bad input: a file, a configuration value, an option, a message. Nothing was changed.
class InputError : public BellowsError {
 public:
  using BellowsError::BellowsError;
  int exit_status() const noexcept override { return kExitBadInput; }
};

/// The engine latched a fault; the valves were vented.
class FaultError : public BellowsError {
 public:
  using BellowsError::BellowsError;
  int exit_status() const noexcept override { return kExitFault; }
};

/// The environment refused: scheduling, memory locking, a bus, a rig, a network address, a disk.
class EnvironmentError : public BellowsError {
 public:
  using BellowsError::BellowsError;
  int exit_status() const noexcept override { return kExitEnvironment; }
};

}  // namespace bellows
