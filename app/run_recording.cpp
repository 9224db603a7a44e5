#include "app/run_recording.hpp"

#include <cmath>
#include <iostream>

#include "app/arm_chain_state_json.hpp"
#include "app/arm_state_json.hpp"
#include "engine/base/errors.hpp"
#include "engine/base/iteration_numbering.hpp"
#include "sessions/session_layout.hpp"
#include "sessions/session_store.hpp"

namespace bellows {
namespace {

constexpr const char* kPurpose = "bellows run";

std::filesystem::path data_dir_of(const RunOptions& options) {
  return options.data_dir.empty() ? default_data_dir() : std::filesystem::path(options.data_dir);
}

}  // namespace

ResumeState capture_resume_state(EngineCore& core, const SimulatedArm* arm, const SimulatedArmChain* chain,
                                 const SimulatedClock* clock) {
  ResumeState resume;
  if (clock == nullptr || (arm == nullptr && chain == nullptr)) return resume;
  resume.controller = core.control().state();
  resume.device = chain != nullptr ? chain_state_to_json(*chain) : arm_state_to_json(*arm);
  resume.clock_ticks = clock->ticks();
  return resume;
}

bool can_restore_exactly(const SessionManifest& manifest) {
  return !manifest.iterations.empty() && manifest.resume && manifest.resume->exact();
}

void restore_resume_state(const SessionManifest& m, SimulatedArm* arm, SimulatedArmChain* chain, EngineCore& core,
                          SimulatedClock* clock, const std::string& source) {
  double arm_time_s = 0.0;
  if (chain != nullptr) {
    restore_chain_state(*chain, m.resume->device, source);
    arm_time_s = chain->chain().state().time_s;
  } else if (arm != nullptr) {
    restore_arm_state(*arm, m.resume->device, source);
    arm_time_s = arm->state().time_s;
  }
  if (clock != nullptr) {
    // A first-format session did not record the clock: it ticked with the arm from 0, so the
    // arm's time in ticks is the clock's (rounded away from the sum's last-place errors).
    const double arm_ticks = arm_time_s / m.configuration.timing.tick_s;
    if (!m.resume->clock_ticks && !(arm_ticks >= 0.0 && arm_ticks < 1e15)) {
      throw InputError(source + ": /resume/device/time_s: expected the arm's time since it started, at least 0");
    }
    clock->set_ticks(m.resume->clock_ticks ? *m.resume->clock_ticks : std::llround(arm_ticks));
  }
  core.restore_armed(*m.resume->controller, clock != nullptr ? clock->now_s() : 0.0);
}

RunRecording::RunRecording(const RunOptions& options) : options_(options), resuming_(!options.resume_dir.empty()) {
  if (!resuming_) return;
  std::filesystem::path data_dir;
  try {
    data_dir = data_dir_of(options);
  } catch (const InputError&) {
    // Without a data directory, --resume needs a path; resolve_session_dir() says so.
  }
  const std::filesystem::path directory = resolve_session_dir(options.resume_dir, data_dir);
  writer_.emplace(SessionWriter::open(directory, kPurpose, resumed_));
  if (const std::string dropped = dropped_line(resumed_); !dropped.empty())
    std::cerr << "bellows: " << dropped << std::endl;
  for (const std::string& log : writer_->kept_logs()) {
    std::cerr << "bellows: kept the LCM log a killed run was writing as " << log << " (its events up to the kill)"
              << std::endl;
  }
  if (resumed_.manifest.device != "sim") {
    throw InputError("session " + directory.string() + " was recorded on the device '" + resumed_.manifest.device +
                     "'; bellows run drives the simulated arm only");
  }
}

std::uint64_t RunRecording::resumed_seed() const {
  const nlohmann::ordered_json& info = resumed_.manifest.device_info;
  const auto seed = info.find("seed");
  if (seed == info.end() || !seed->is_number_unsigned()) {
    throw InputError("session " + resumed_.directory.string() + ": " + session_layout::kManifest +
                     ": /device_info/seed: expected a whole number, the simulated arm's seed");
  }
  return seed->get<std::uint64_t>();
}

int RunRecording::trials(int iterations) const {
  return trials_for_iterations(iterations, resuming_ && !resumed_.manifest.iterations.empty());
}

void RunRecording::start(const Configuration& config, const Trajectory& trajectory, const std::string& device,
                         std::uint64_t seed, int iterations, const nlohmann::ordered_json& device_info,
                         const std::string& model_source, const nlohmann::ordered_json& first_correction) {
  if (options_.no_save || resuming_) return;
  SessionManifest header;
  header.device = device;
  header.device_info = device_info;
  header.configuration = config;
  header.model_source = model_source;
  header.first_correction = first_correction;
  header.events.push_back({utc_now(), 0, "start",
                           std::string(kPurpose) + ": trajectory " + trajectory.name + ", " +
                               std::to_string(iterations) + " iterations, seed " + std::to_string(seed)});
  writer_.emplace(
      SessionWriter::create(data_dir_of(options_), options_.session_name, std::move(header), trajectory, kPurpose));
}

void RunRecording::require_joints(int joints, const std::string& arm) const {
  if (resumed_.manifest.joints != joints) {
    throw InputError("session " + resumed_.directory.string() + " was recorded with an arm of " +
                     std::to_string(resumed_.manifest.joints) + " joint" + (resumed_.manifest.joints == 1 ? "" : "s") +
                     "; this run drives " + arm + " of " + std::to_string(joints) +
                     " (its [arm] preset must be the session's)");
  }
}

void RunRecording::record_resumption() {
  writer_->record_event(
      "resume", std::string(kPurpose) + " --resume: " + std::to_string(options_.iterations) + " more iterations");
}

void RunRecording::restore(SimulatedArm* arm, EngineCore& core, SimulatedClock* clock, LearningSession& learning) {
  if (!resuming_) return;
  require_joints(learning.joints(), "an arm");
  const SessionManifest& m = resumed_.manifest;
  if (!resumed_.iterations.empty()) {  // else nothing completed: start afresh
    if (can_restore_exactly(m) && arm != nullptr) {
      restore_resume_state(m, arm, nullptr, core, clock,
                           "session " + resumed_.directory.string() + ": " + session_layout::kManifest);
    }
    learning.set_correction(resumed_corrections_bar(), static_cast<int>(m.iterations.size()));
    learning.set_history(resumed_history());
  }
  record_resumption();
}

void RunRecording::restore(SimulatedArmChain* arm, EngineCore& core, SimulatedClock* clock, LearningSession& learning) {
  if (!resuming_) return;
  require_joints(learning.joints(), "an arm");
  restore(arm, core, clock);
  if (!resumed_.iterations.empty()) {
    learning.set_correction(resumed_corrections_bar(), static_cast<int>(resumed_.manifest.iterations.size()));
    learning.set_history(resumed_history());
  }
}

void RunRecording::restore(SimulatedArmChain* arm, EngineCore& core, SimulatedClock* clock) {
  if (!resuming_) return;
  const SessionManifest& m = resumed_.manifest;
  if (arm != nullptr) require_joints(arm->joints(), "a simulated arm");
  if (!resumed_.iterations.empty() && can_restore_exactly(m) && arm != nullptr) {
    restore_resume_state(m, nullptr, arm, core, clock,
                         "session " + resumed_.directory.string() + ": " + session_layout::kManifest);
  }
  record_resumption();
}

Eigen::MatrixXd RunRecording::resumed_corrections_bar() const {
  if (!resuming_ || resumed_.iterations.empty()) return {};
  return resumed_.iterations.back().next_corrections_bar();
}

std::vector<IterationSummary> RunRecording::resumed_history() const {
  std::vector<IterationSummary> history;
  if (!resuming_) return history;
  for (const IterationEntry& entry : resumed_.manifest.iterations) history.push_back(entry.summary);
  return history;
}

void RunRecording::save(const LearningSession& learning, const IterationSummary& summary, const SimulatedArm* arm,
                        EngineCore& core, const SimulatedClock* clock) {
  if (!writer_) return;
  // Same thread as the engine: its state is quiet between trials.
  writer_->save_iteration(learning.last_record(), summary, learning.joint_corrections_bar(),
                          capture_resume_state(core, arm, nullptr, clock));
}

void RunRecording::save(const LearningSession& learning, const IterationSummary& summary, const SimulatedArmChain* arm,
                        EngineCore& core, const SimulatedClock* clock) {
  save(learning.last_record(), learning.joint_corrections_bar(), summary, arm, core, clock);
}

void RunRecording::save(const TrialRecord& record, const Eigen::MatrixXd& corrections_bar,
                        const IterationSummary& summary, const SimulatedArmChain* arm, EngineCore& core,
                        const SimulatedClock* clock) {
  if (!writer_) return;
  // As above: between trials, on the engine's thread.
  writer_->save_iteration(record, summary, corrections_bar, capture_resume_state(core, nullptr, arm, clock));
}

void RunRecording::fault(const std::string& what) noexcept {
  if (!writer_) return;
  try {
    writer_->record_event("fault", what);
  } catch (...) {
    // The session keeps every completed iteration either way; the caller reports the fault.
  }
}

void RunRecording::fault(const std::string& what, const EngineCore& core) noexcept {
  if (!writer_) return;
  try {
    const std::vector<TickRecord> ticks = core.black_box().copy_frozen();
    if (!ticks.empty()) writer_->save_black_box(fault_name(core.fault()), ticks);
  } catch (...) {
    // As above: the event below still says what happened.
  }
  fault(what);
}

void RunRecording::note(const std::string& kind, const std::string& message) noexcept {
  if (!writer_) return;
  try {
    writer_->record_event(kind, message);
  } catch (...) {
    // The report says it too.
  }
}

void RunRecording::finish(int trials_run) {
  if (writer_)
    writer_->record_event("finish", std::string(kPurpose) + ": " + std::to_string(trials_run) + " trials done");
}

std::filesystem::path RunRecording::directory() const {
  return writer_ ? writer_->directory() : std::filesystem::path();
}

}  // namespace bellows
