#include "app/transfer_sources.hpp"

#include <cmath>
#include <cstdio>

#include "engine/base/errors.hpp"
#include "sessions/session_store.hpp"

namespace bellows {
namespace {

std::string describe(const Session& session) {
  const std::string name =
      session.manifest.name.empty() ? session.directory.filename().string() : session.manifest.name;
  return "session '" + name + "'";
}

}  // namespace

JointTransferSource transfer_source_from_session(const Session& session) {
  std::vector<const TrialRecord*> records;
  for (const IterationData& iteration : session.iterations) records.push_back(&iteration.record);
  return joint_transfer_source(
      session.manifest.name.empty() ? session.directory.filename().string() : session.manifest.name, session.trajectory,
      session.manifest.configuration.controller, records);
}

void check_transfer_source(const Session& session, const Configuration& target, const std::string& device,
                           const std::string& rig_profile) {
  if (const std::string why =
          transfer_mismatch(session.manifest.configuration, session.manifest.device, target, device);
      !why.empty()) {
    throw InputError("cannot transfer from " + describe(session) + ": " + why);
  }
  if (const std::string why = rig_profile_mismatch(rig_profile_of(session.manifest), rig_profile); !why.empty()) {
    throw InputError("cannot transfer from " + describe(session) + ": " + why);
  }
  if (session.iterations.empty())
    throw InputError("cannot transfer from " + describe(session) + ": it has no completed trial");
}

std::vector<Session> load_transfer_sessions(const std::vector<std::string>& names,
                                            const std::filesystem::path& data_dir, const Configuration& target,
                                            const std::string& device, const std::string& rig_profile) {
  std::vector<Session> sessions;
  for (const std::string& name : names) {
    Session session = load_session(resolve_session_dir(name, data_dir));
    check_transfer_source(session, target, device, rig_profile);
    sessions.push_back(std::move(session));
  }
  return sessions;
}

TransferReport compute_transfer(const std::vector<Session>& sessions, const Configuration& config,
                                const Trajectory& target, TransferMethod method) {
  TransferReport report;
  std::vector<JointTransferSource> sources;
  for (const Session& session : sessions) {
    sources.push_back(transfer_source_from_session(session));
    const IterationEntry* last = session.manifest.iterations.empty() ? nullptr : &session.manifest.iterations.back();
    report.sources.push_back({sources.back().name, session.directory.string(), session.trajectory.name,
                              sources.back().trials(), last != nullptr ? last->summary.rms_deg : 0.0});
  }
  TransferSettings settings;
  settings.method = method;
  report.result = transfer_every_joint(sources, config.controller, config.timing.sample_s(), target, settings);
  return report;
}

namespace {

/// One joint's transfer: method, status, why it fell back, its prediction and validation.
nlohmann::json joint_transfer_json(const TransferResult& r) {
  nlohmann::json methods = nlohmann::json::object();
  for (const auto& [name, ratio] : r.method_ratios)
    methods[name] = std::isfinite(ratio) ? nlohmann::json(ratio) : nlohmann::json(nullptr);
  const bool applied = r.status == TransferStatus::kTransferred;
  return {{"method", r.method},
          {"status", applied ? "transferred" : "fallback"},
          {"reason", applied ? nlohmann::json(nullptr) : nlohmann::json(r.reason)},
          {"prediction",
           {{"feedback_only_rms_deg", r.predicted_feedback_only_rms_deg},
            {"rms_deg", r.predicted_rms_deg},
            {"ratio",
             r.predicted_feedback_only_rms_deg > 0.0 ? r.predicted_rms_deg / r.predicted_feedback_only_rms_deg : 1.0}}},
          {"validation_ratio",
           std::isfinite(r.validation_ratio) ? nlohmann::json(r.validation_ratio) : nlohmann::json(nullptr)},
          {"method_validation_ratios", methods},
          {"clamped_samples", r.clamped_samples},
          {"max_abs_correction_bar", r.correction_bar.size() > 0 ? r.correction_bar.cwiseAbs().maxCoeff() : 0.0}};
}

/// "inverse-fir, predicted first trial 1.90 deg RMS (feedback only 8.60 deg)" or "none: <why>".
std::string joint_transfer_words(const TransferResult& r) {
  char words[256];
  if (r.status == TransferStatus::kTransferred) {
    std::snprintf(words, sizeof words, "%s, predicted first trial %.2f deg RMS (feedback only %.2f deg)",
                  r.method.c_str(), r.predicted_rms_deg, r.predicted_feedback_only_rms_deg);
    return words;
  }
  return "none, the first trial runs with feedback only: " + r.reason;
}

}  // namespace

nlohmann::json transfer_json(const TransferReport& report) {
  const JointTransferResult& r = report.result;
  nlohmann::json sources = nlohmann::json::array();
  for (const TransferSourceInfo& s : report.sources) {
    sources.push_back({{"session", s.name},
                       {"directory", s.directory},
                       {"trajectory", s.trajectory},
                       {"trials", s.trials},
                       {"last_rms_deg", s.last_rms_deg}});
  }
  if (r.joints.size() == 1) {  // one joint: its transfer's fields beside the sources
    nlohmann::json out = joint_transfer_json(r.joints.front());
    out["sources"] = sources;
    return out;
  }
  nlohmann::json joints = nlohmann::json::array();
  for (std::size_t j = 0; j < r.joints.size(); ++j) {
    joints.push_back(joint_transfer_json(r.joints[j]));
    joints.back()["joint"] = j + 1;
  }
  const double feedback_only = r.predicted_feedback_only_rms_deg();
  return {{"sources", sources},
          {"status", r.transferred() ? "transferred" : "fallback"},
          {"prediction",
           {{"feedback_only_rms_deg", feedback_only},
            {"rms_deg", r.predicted_rms_deg()},
            {"ratio", feedback_only > 0.0 ? r.predicted_rms_deg() / feedback_only : 1.0}}},
          {"max_abs_correction_bar", r.correction_bar.size() > 0 ? r.correction_bar.cwiseAbs().maxCoeff() : 0.0},
          {"joints", joints}};
}

std::string transfer_line(const TransferReport& report) {
  std::string names;
  for (const TransferSourceInfo& s : report.sources) names += (names.empty() ? "" : ", ") + s.name;
  const JointTransferResult& r = report.result;
  if (r.joints.size() == 1) return "transfer from " + names + ": " + joint_transfer_words(r.joints.front());
  std::string line = "transfer from " + names + ":";
  for (std::size_t j = 0; j < r.joints.size(); ++j)
    line += (j == 0 ? " joint " : "; joint ") + std::to_string(j + 1) + " " + joint_transfer_words(r.joints[j]);
  char total[160];
  std::snprintf(total, sizeof total, "; the arm's first trial predicted %.2f deg RMS (feedback only %.2f deg)",
                r.predicted_rms_deg(), r.predicted_feedback_only_rms_deg());
  return line + total;
}

}  // namespace bellows
