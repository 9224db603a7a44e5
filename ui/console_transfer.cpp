#include "ui/console_transfer.hpp"

#include <algorithm>
#include <exception>

#include "ui/canvas.hpp"
#include "ui/console_controller.hpp"

namespace bellows::ui {

std::string TransferOffer::offer_line() const {
  return format("%c: start from what %d session%s taught (%s): predicted %.1f deg RMS, feedback only %.1f deg",
                kTransferKey, source_count, source_count == 1 ? "" : "s", method.c_str(), predicted_rms_deg,
                feedback_only_rms_deg);
}

JointTransferSource transfer_source_of(const Experiment& experiment, const Configuration& config) {
  if (!experiment.trajectory) return {};
  std::vector<const TrialRecord*> records;
  for (const Trial& trial : experiment.trials) {
    if (trial.record.complete) records.push_back(&trial.record);
  }
  return joint_transfer_source(experiment.trajectory->name, *experiment.trajectory, config.controller, records);
}

TransferSourceNote transfer_note_of(const Experiment& experiment, std::string name) {
  TransferSourceNote note;
  note.name = std::move(name);
  note.directory = experiment.session_location;
  note.trajectory = experiment.trajectory ? experiment.trajectory->name : "";
  note.trials = static_cast<int>(experiment.trials.size());
  note.last_rms_deg = experiment.trials.empty() ? 0.0 : experiment.trials.back().summary.rms_deg;
  return note;
}

TransferOffer compute_transfer_offer(std::vector<JointTransferSource> taught, SessionGateway* sessions,
                                     const Configuration& config, const std::string& device,
                                     const std::string& rig_profile, const std::shared_ptr<const Trajectory>& target,
                                     int max_saved, const std::vector<std::string>& taught_locations,
                                     const std::vector<TransferSourceNote>& taught_notes) {
  TransferOffer offer;
  offer.trajectory = target;
  try {
    std::vector<JointTransferSource> sources;
    auto record = std::make_shared<FirstCorrection>();
    for (std::size_t i = 0; i < taught.size(); ++i) {
      JointTransferSource& s = taught[i];
      if (s.trials() == 0 || static_cast<int>(s.joints.size()) != target->joints()) continue;
      record->sources.push_back(i < taught_notes.size() ? taught_notes[i]
                                                        : TransferSourceNote{s.name, "", s.name, 0, 0.0});
      record->sources.back().trials = s.trials();
      sources.push_back(std::move(s));
    }
    if (sessions != nullptr && sessions->available()) {
      std::vector<SessionListing> listed = sessions->list();
      std::reverse(listed.begin(), listed.end());  // newest first
      int used = 0;
      for (const SessionListing& listing : listed) {
        if (used >= max_saved) break;
        if (!listing.error.empty() || listing.iterations == 0) continue;
        if (std::find(taught_locations.begin(), taught_locations.end(), listing.location) != taught_locations.end())
          continue;
        try {
          const SessionSnapshot snapshot = sessions->read_trials(listing.location);
          if (!transfer_mismatch(snapshot.config, snapshot.device_name, config, device).empty()) continue;
          if (!rig_profile_mismatch(snapshot.rig_profile, rig_profile).empty())
            continue;  // another arm, or wired otherwise
          JointTransferSource source = transfer_source_of(snapshot.experiment, snapshot.config);
          if (source.trials() == 0 || static_cast<int>(source.joints.size()) != target->joints()) continue;
          source.name = listing.name + " (saved)";
          TransferSourceNote note = transfer_note_of(snapshot.experiment, listing.name);
          note.directory = listing.location;
          record->sources.push_back(std::move(note));
          sources.push_back(std::move(source));
          ++used;
        } catch (const std::exception&) {
          continue;  // an unreadable session teaches nothing; the browser says why
        }
      }
    }
    if (sources.empty()) {
      offer.why_not = "no earlier trials of this arm to learn from";
      return offer;
    }
    for (const JointTransferSource& s : sources) offer.sources += (offer.sources.empty() ? "" : ", ") + s.name;
    offer.source_count = static_cast<int>(sources.size());
    JointTransferResult result =
        transfer_every_joint(sources, config.controller, config.timing.sample_s(), *target, TransferSettings{});
    for (const TransferResult& joint : result.joints) {
      const bool applied = joint.status == TransferStatus::kTransferred;
      offer.method +=
          (offer.method.empty() ? "" : " / ") + (applied || result.joints.size() == 1 ? joint.method : "none");
    }
    offer.predicted_rms_deg = result.predicted_rms_deg();
    offer.feedback_only_rms_deg = result.predicted_feedback_only_rms_deg();
    if (!result.transferred()) {
      for (const TransferResult& joint : result.joints)
        offer.why_not += (offer.why_not.empty() ? "" : "; ") + joint.reason;
      return offer;
    }
    offer.correction_bar = result.correction_bar;
    offer.useful = true;
    record->result = std::move(result);
    offer.record = std::move(record);
  } catch (const std::exception& error) {
    offer.why_not = error.what();
  }
  return offer;
}

// The controller's side: remembering what was taught, offering, taking the offer.

void ConsoleController::remember_taught() {
  JointTransferSource source = transfer_source_of(state_.experiment, env_.config);
  if (source.trials() == 0) return;
  taught_.push_back(std::move(source));
  taught_notes_.push_back(transfer_note_of(state_.experiment, state_.experiment.trajectory->name + " (this console)"));
  if (!state_.experiment.session_location.empty()) taught_locations_.push_back(state_.experiment.session_location);
}

void ConsoleController::offer_transfer() {
  transfer_offer_ = TransferOffer{};
  if (!state_.experiment.trials.empty() || state_.experiment.next_correction_bar.cwiseAbs().maxCoeff() > 0.0) return;
  if (transfer_task_.busy()) {  // one at a time: ask again when the running one is done
    transfer_wanted_ = true;
    return;
  }
  transfer_wanted_ = false;
  transfer_task_.start([taught = taught_, notes = taught_notes_, locations = taught_locations_,
                        sessions = env_.sessions, config = env_.config, device = env_.device_name,
                        profile = env_.rig_profile, target = state_.experiment.trajectory] {
    return compute_transfer_offer(taught, sessions, config, device, profile, target, 4, locations, notes);
  });
}

void ConsoleController::poll_transfer() {
  if (!transfer_task_.ready()) return;
  TransferOffer offer = transfer_task_.take();
  ++revision_;
  if (transfer_wanted_ || offer.trajectory != state_.experiment.trajectory) {
    offer_transfer();  // computed for a trajectory no longer selected
    return;
  }
  if (!state_.experiment.trials.empty()) return;
  if (!offer.useful) {
    if (offer.source_count > 0) log(LogSource::kLearner, "no transfer offered: " + offer.why_not, false, -2.0, true);
    return;
  }
  log(LogSource::kLearner, "transfer from " + offer.sources + " ready: " + offer.offer_line());
  set_status(offer.offer_line());
  transfer_offer_ = std::move(offer);
}

bool ConsoleController::handle_transfer_key(int k) {
  if (k != kTransferKey || state_.screen != Screen::kMain) return false;
  if (!transfer_offer_.useful || transfer_offer_.trajectory != state_.experiment.trajectory) {
    set_status(format("%c: no transfer is offered for this trajectory (offered when one with no correction is chosen)",
                      kTransferKey),
               true);
    return true;
  }
  if (!state_.experiment.trials.empty() || state_.run.mode != RunProgress::Mode::kIdle) {
    set_status(format("%c: a transfer starts a trajectory; this one has trials already", kTransferKey), true);
    return true;
  }
  const TransferOffer& o = transfer_offer_;
  state_.experiment.set_next(o.correction_bar, "transferred (" + o.method + ")");
  state_.experiment.first_correction = o.record;  // the session records it with iteration 0
  log(LogSource::kOperator,
      format("first correction transferred from %s (%s): predicted %.2f deg RMS, feedback only %.2f deg",
             o.sources.c_str(), o.method.c_str(), o.predicted_rms_deg, o.feedback_only_rms_deg));
  set_status(format("iteration 0 runs with the transferred correction: predicted %.1f deg RMS", o.predicted_rms_deg));
  transfer_offer_ = TransferOffer{};
  return true;
}

}  // namespace bellows::ui
