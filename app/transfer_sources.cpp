#include "app/transfer_sources.hpp"

#include <cmath>

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

TransferSource transfer_source_from_session(const Session& session) {
  TransferSource source;
  source.name = session.manifest.name.empty() ? session.directory.filename().string() : session.manifest.name;
  source.trajectory = session.trajectory;
  source.controller = session.manifest.configuration.controller;
  const Eigen::Index n = session.trajectory.learning_samples();
  for (const IterationData& iteration : session.iterations) {
    const TrialSamples& s = iteration.record.joint_samples(0);
    if (s.u_ilc_bar.size() < n || s.u_pid_bar.size() < n || s.angle_rad.size() < n + 1) continue;
    source.trials.push_back({s.u_ilc_bar.head(n), s.u_pid_bar.head(n), s.angle_rad.head(n + 1)});
  }
  return source;
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
  std::vector<TransferSource> sources;
  for (const Session& session : sessions) {
    sources.push_back(transfer_source_from_session(session));
    const IterationEntry* last = session.manifest.iterations.empty() ? nullptr : &session.manifest.iterations.back();
    report.sources.push_back({sources.back().name, session.directory.string(), session.trajectory.name,
                              static_cast<int>(sources.back().trials.size()),
                              last != nullptr ? last->summary.rms_deg : 0.0});
  }
  TransferSettings settings;
  settings.method = method;
  LearningTransfer transfer(settings);
  transfer.setup(std::move(sources), config.controller, config.timing.sample_s());
  report.result = transfer.solve(target);
  return report;
}

nlohmann::json transfer_json(const TransferReport& report) {
  const TransferResult& r = report.result;
  nlohmann::json sources = nlohmann::json::array();
  for (const TransferSourceInfo& s : report.sources) {
    sources.push_back({{"session", s.name},
                       {"directory", s.directory},
                       {"trajectory", s.trajectory},
                       {"trials", s.trials},
                       {"last_rms_deg", s.last_rms_deg}});
  }
  nlohmann::json methods = nlohmann::json::object();
  for (const auto& [name, ratio] : r.method_ratios)
    methods[name] = std::isfinite(ratio) ? nlohmann::json(ratio) : nlohmann::json(nullptr);
  const bool applied = r.status == TransferStatus::kTransferred;
  return {{"sources", sources},
          {"method", r.method},
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

std::string transfer_line(const TransferReport& report) {
  std::string names;
  for (const TransferSourceInfo& s : report.sources) names += (names.empty() ? "" : ", ") + s.name;
  const TransferResult& r = report.result;
  char line[256];
  if (r.status == TransferStatus::kTransferred) {
    std::snprintf(line, sizeof line, ": %s, predicted first trial %.2f deg RMS (feedback only %.2f deg)",
                  r.method.c_str(), r.predicted_rms_deg, r.predicted_feedback_only_rms_deg);
    return "transfer from " + names + line;
  }
  return "transfer from " + names + ": none, the first trial runs with feedback only: " + r.reason;
}

}  // namespace bellows
