// Saved sessions as the sources of a learning transfer (engine/config/learning_transfer): loading them,
// refusing those that cannot teach the target run, and the report (`bellows run --json`'s
// "transfer", the progress line, the session's `first_correction`).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "engine/config/configuration.hpp"
#include "engine/config/joint_transfer.hpp"
#include "sessions/session.hpp"

namespace bellows {

/// Where a source came from, for the report.
struct TransferSourceInfo {
  std::string name;  // the session's name
  std::string directory;
  std::string trajectory;  // its trajectory's name
  int trials = 0;
  double last_rms_deg = 0.0;
};

/// The trials of `session` as a transfer source, every joint's.
JointTransferSource transfer_source_from_session(const Session& session);

/// Checks that `session` can teach a run of `target` on `device`: same sample time, same device, the
/// same simulated plant ([plant]: the same arm) and, on a rig, the same rig profile (`rig_profile`:
/// its name; empty: not compared). Throws InputError naming the session and why.
void check_transfer_source(const Session& session, const Configuration& target, const std::string& device,
                           const std::string& rig_profile = {});

/// Loads and checks every session (`names`: directories or names in `data_dir`). InputError names the
/// first session that is missing, damaged, empty or does not fit.
std::vector<Session> load_transfer_sessions(const std::vector<std::string>& names,
                                            const std::filesystem::path& data_dir, const Configuration& target,
                                            const std::string& device, const std::string& rig_profile = {});

struct TransferReport {
  std::vector<TransferSourceInfo> sources;
  JointTransferResult result;  // every joint's
};

/// Sets up the transfer of every joint from `sessions` and solves it for `target`.
TransferReport compute_transfer(const std::vector<Session>& sessions, const Configuration& config,
                                const Trajectory& target, TransferMethod method = TransferMethod::kAuto);

/// One joint: {"sources": [...], "method", "status", "reason", "prediction": {...}, ...}. Several:
/// {"sources", "status" (transferred when any joint was), "prediction" (over every joint),
/// "max_abs_correction_bar", "joints": [{"joint", "method", "status", "reason", "prediction", ...}]}.
nlohmann::json transfer_json(const TransferReport& report);
/// One line for the progress stream, e.g. "transfer from a, b: inverse-fir, predicted first trial 1.9 deg RMS
/// (feedback only 8.6 deg)" or "transfer from a: none, the first trial runs with feedback only: <why>";
/// several joints: each joint's after "joint j", then the arm's predicted first trial.
std::string transfer_line(const TransferReport& report);

}  // namespace bellows
