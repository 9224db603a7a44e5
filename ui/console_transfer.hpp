// Learning transfer in the console (issue 13): when the operator selects a trajectory that has no
// correction yet, what the earlier experiments of this console and the saved sessions taught is
// turned into a first correction on a worker thread (engine/config/joint_transfer, every joint's); the console offers
// it with its prediction, and `T` takes it. The taught experiments are kept when the operator moves
// on to another trajectory.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "engine/config/configuration.hpp"
#include "engine/config/joint_transfer.hpp"
#include "ui/experiment.hpp"
#include "ui/key_map.hpp"
#include "ui/session_gateway.hpp"

namespace bellows::ui {

struct TransferOffer {
  bool useful = false;
  std::shared_ptr<const Trajectory> trajectory;  // what it was computed for
  Eigen::MatrixXd correction_bar;                // N x J
  std::string method;                            // several joints: each joint's, "inverse-fir / none"
  std::string sources;                           // "paper, steps (saved)"
  int source_count = 0;
  double predicted_rms_deg = 0.0;
  double feedback_only_rms_deg = 0.0;
  std::string why_not;                            // when not useful
  std::shared_ptr<const FirstCorrection> record;  // what the session records when it is taken
  /// "T: start from what 2 sessions taught (inverse-fir): predicted 2.0 deg RMS, feedback only 12.6 deg"
  std::string offer_line() const;
};

/// An experiment's complete trials as a transfer source, every joint's; no trials when it has none
/// with a record.
JointTransferSource transfer_source_of(const Experiment& experiment, const Configuration& config);

/// Worker thread: the transfer from `taught` (this console's earlier experiments) and the `max_saved`
/// newest saved sessions that fit this run (transfer_mismatch; on a rig, the same rig profile:
/// rig_profile_mismatch against `rig_profile`, "" without one), for `target`. Never throws: a
/// transfer that cannot be computed or would not help comes back with `why_not`. `taught_locations`:
/// where `taught` is saved; `taught_notes`: one per `taught` source, for the record (the console saves as it goes), so
/// the same trials are not used twice.
TransferOffer compute_transfer_offer(std::vector<JointTransferSource> taught, SessionGateway* sessions,
                                     const Configuration& config, const std::string& device,
                                     const std::string& rig_profile, const std::shared_ptr<const Trajectory>& target,
                                     int max_saved = 4, const std::vector<std::string>& taught_locations = {},
                                     const std::vector<TransferSourceNote>& taught_notes = {});
/// `experiment`'s trials as a transfer source's note (what a session records about it).
TransferSourceNote transfer_note_of(const Experiment& experiment, std::string name);

}  // namespace bellows::ui
