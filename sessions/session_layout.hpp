// File names inside a session directory (docs/session-format.md). Derived from the iteration
// number, never taken from the manifest, so a damaged manifest cannot point outside the session.
#pragma once

#include <cstdio>
#include <string>

namespace bellows::session_layout {

inline constexpr const char* kManifest = "manifest.json";
inline constexpr const char* kTrajectory = "trajectory.csv";
inline constexpr const char* kIterations = "iterations";
inline constexpr const char* kFaults = "faults";

inline std::string numbered(const char* stem, int iteration, const char* folder = kIterations) {
  char name[48];
  std::snprintf(name, sizeof name, "%s/%s_%04d.csv", folder, stem, iteration);
  return name;
}
/// ILC-rate samples of one iteration, relative to the session directory.
inline std::string samples_file(int iteration) { return numbered("iteration", iteration); }
/// Tick-rate telemetry of one iteration, relative to the session directory.
inline std::string telemetry_file(int iteration) { return numbered("telemetry", iteration); }
/// The black box of the session's fault number `index` (0, 1, ...), relative to the session directory.
inline std::string black_box_file(int index) { return numbered("blackbox", index, kFaults); }

}  // namespace bellows::session_layout
