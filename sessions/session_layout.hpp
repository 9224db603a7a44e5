// File names inside a session directory (docs/session-format.md). Derived from the iteration
// number, never taken from the manifest, so a damaged manifest cannot point outside the session.
#pragma once

#include <cstdio>
#include <cstddef>
#include <string>
#include <utility>

namespace bellows::session_layout {

inline constexpr const char* kManifest = "manifest.json";
inline constexpr const char* kTrajectory = "trajectory.csv";
inline constexpr const char* kIterations = "iterations";
inline constexpr const char* kFaults = "faults";

/// The largest manifest read: about 150 000 iterations (a paper session's is about 50 KB). Parsing
/// JSON takes several times its size in memory, so this bound keeps a bad file from exhausting it.
inline constexpr std::size_t kMostManifestBytes = std::size_t{64} << 20;

inline std::string numbered(const char* stem, int iteration, const char* folder = kIterations) {
  char name[48];
  std::snprintf(name, sizeof name, "%s/%s_%04d.csv", folder, stem, iteration);
  return name;
}
/// ILC-rate samples of one iteration, relative to the session directory. `revision` counts how
/// often the correction learned from it was replaced after its save (the console learns after
/// saving): each replacement is a new file, "iteration_0004.r1.csv", and the manifest's switch to
/// it is the commit, so a committed file is never rewritten in place.
inline std::string samples_file(int iteration, int revision = 0) {
  std::string name = numbered("iteration", iteration);
  if (revision > 0) name.insert(name.size() - 4, ".r" + std::to_string(revision));
  return name;
}
/// The most revisions of one iteration's samples file a manifest may name.
inline constexpr int kMostSamplesRevisions = 1000000;
/// Tick-rate telemetry of one iteration, relative to the session directory.
inline std::string telemetry_file(int iteration) { return numbered("telemetry", iteration); }
/// The black box of the session's fault number `index` (0, 1, ...), relative to the session directory.
inline std::string black_box_file(int index) { return numbered("blackbox", index, kFaults); }

/// "iterations/iteration_0001.csv" -> {"iterations", "iteration_0001.csv"}; a top-level name
/// gets an empty folder.
inline std::pair<std::string, std::string> folder_and_name(const std::string& relative) {
  const std::size_t slash = relative.find('/');
  if (slash == std::string::npos) return {"", relative};
  return {relative.substr(0, slash), relative.substr(slash + 1)};
}

}  // namespace bellows::session_layout
