// Channel names and the default bus of the bellows LCM protocol (docs/lcm-protocol.md).
#pragma once

namespace bellows {

inline constexpr const char* kIoCommandChannel = "BELLOWS_IO_COMMAND";  // io_command_t, engine -> rig
inline constexpr const char* kIoStateChannel = "BELLOWS_IO_STATE";      // io_state_t, rig -> engine
inline constexpr const char* kIoLimitsChannel = "BELLOWS_IO_LIMITS";    // io_rig_limits_t, rig -> engine
inline constexpr double kIoLimitsPeriod_s = 1.0;  // a rig announces its limits at its start, then this often
inline constexpr const char* kTelemetryChannel = "BELLOWS_TELEMETRY";  // telemetry_t, every tick
inline constexpr const char* kTrialChannel = "BELLOWS_TRIAL";          // trial_summary_t, every trial
inline constexpr const char* kEventChannel = "BELLOWS_EVENT";          // engine_event_t

/// UDP multicast on the local host only (ttl=0): what a lab uses unless it names another bus.
inline constexpr const char* kDefaultLcmUrl = "udpm://239.255.76.67:7667?ttl=0";

}  // namespace bellows
