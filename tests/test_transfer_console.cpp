// The console's learning transfer (ui/console_transfer): after trials on one trajectory, choosing
// another with no correction offers (key T, prediction shown) to start from what was taught; taking
// it makes iteration 0 run with it; the inspector keeps the transferred correction in view.
#include <gtest/gtest.h>

#include "console_fixture.hpp"
#include "test_transfer_scenarios.hpp"
#include "ui/console_transfer.hpp"
#include "ui/plot_data.hpp"

namespace bellows {
namespace {

using testing::ConsoleFixture;
using ui::key::kDown;
using ui::key::kEnter;

void choose_steps(ConsoleFixture& f) {
  f.key('t');
  f.key(kDown);  // steps
  f.key(kEnter);
  if (f.state().dialog.kind == ui::DialogKind::kConfirmDiscard) f.key('y');
  ASSERT_EQ(f.state().experiment.trajectory->name, "steps");
}

TEST(ConsoleTransfer, OffersWhatTheLastTrajectoryTaughtAndTakesItWithOneKey) {
  ConsoleFixture f;
  f.key('T');  // nothing taught yet
  EXPECT_NE(f.state().status.find("no transfer is offered"), std::string::npos) << f.state().status;
  f.arm_valves();
  f.run_batch(7);  // iterations 0..7 (docs/iterations.md)
  ASSERT_EQ(f.state().experiment.trials.size(), 8u);
  // The first autosave's note ("saved as it goes") is a status too: let it land before the offer
  // it would otherwise replace on a loaded machine.
  // (The location is known when the save starts; its note comes when it ends: wait for the end.)
  ASSERT_TRUE(
      f.pump_until([&] { return !f.state().experiment.session_location.empty() && f.console->saves_settled(); }));
  choose_steps(f);
  ASSERT_TRUE(f.pump_until([&] { return f.state().status.find("T: start from what") != std::string::npos; }, 50.0))
      << f.state().status;
  EXPECT_NE(f.state().status.find("predicted"), std::string::npos);
  EXPECT_NE(f.state().status.find("feedback only"), std::string::npos);
  EXPECT_TRUE(f.logged("transfer from paper ready"));

  f.key('T');
  EXPECT_EQ(f.state().experiment.next_origin.rfind("transferred", 0), 0u) << f.state().experiment.next_origin;
  EXPECT_GT(f.state().experiment.next_correction_bar.cwiseAbs().maxCoeff(), 0.0);
  EXPECT_TRUE(f.logged("first correction transferred from paper"));
  ASSERT_TRUE(f.pump_until([&] { return f.state().law_ready; }));
  f.key('r');
  ASSERT_TRUE(f.pump_until([&] { return f.idle(); }));
  ASSERT_EQ(f.state().experiment.trials.size(), 1u);
  EXPECT_EQ(f.state().experiment.trials[0].origin.rfind("transferred", 0), 0u);
  const Configuration config;
  const double feedback_only =
      testing::run_learning(config, library_trajectory("steps", config.timing.sample_s()), 0).rms_deg[0];
  EXPECT_LT(f.state().experiment.trials[0].summary.rms_deg, 0.6 * feedback_only);
  f.key('T');  // the trajectory has a trial now: no second transfer
  EXPECT_NE(f.state().status.find("no transfer is offered"), std::string::npos) << f.state().status;
}

// On a rig, a saved session teaches only a console on the same rig profile (as `bellows run
// --transfer-from` checks): another profile is another arm, or the same arm wired otherwise.
TEST(ConsoleTransfer, SavedSessionsOfAnotherRigProfileAreNotOffered) {
  ConsoleFixture f;
  f.arm_valves();
  f.run_batch(4);
  ASSERT_TRUE(f.pump_until([&] { return f.sessions.saves > 0 && f.idle(); }));
  ui::SessionSnapshot recorded;
  {
    const std::lock_guard<std::mutex> guard(f.sessions.mutex);
    ASSERT_EQ(f.sessions.saved.size(), 1u);
    recorded = f.sessions.saved.begin()->second;
  }
  ASSERT_FALSE(recorded.experiment.trials.empty());
  recorded.device_name = "t7";  // as if recorded through a T7
  const auto steps = std::make_shared<const Trajectory>(library_trajectory("steps", f.config.timing.sample_s()));
  const auto offer_from = [&](const std::string& their_profile, const std::string& our_profile) {
    testing::MemorySessions saved;
    ui::SessionSnapshot s = recorded;
    s.rig_profile = their_profile;
    s.experiment.session_location = "mem://rig";
    saved.saved["mem://rig"] = s;
    return ui::compute_transfer_offer({}, &saved, f.config, "t7", our_profile, steps);
  };
  const ui::TransferOffer same = offer_from("paper-rig", "paper-rig");
  EXPECT_EQ(same.source_count, 1) << same.why_not;
  EXPECT_EQ(same.sources, "mem://rig (saved)");
  const ui::TransferOffer other = offer_from("other-rig", "paper-rig");
  EXPECT_EQ(other.source_count, 0);
  EXPECT_FALSE(other.useful);
  EXPECT_EQ(other.why_not, "no earlier trials of this arm to learn from");
  const ui::TransferOffer none = offer_from("", "paper-rig");  // recorded without a profile: not this rig's
  EXPECT_EQ(none.source_count, 0);
}

TEST(ConsoleTransfer, TheInspectorKeepsTheTransferredCorrectionInView) {
  ui::Experiment e = ui::Experiment::start(std::make_shared<const Trajectory>(library_trajectory("paper", 0.02)));
  for (int i = 0; i < 3; ++i) {
    ui::Trial t;
    t.iteration = i;
    t.correction_bar = Eigen::VectorXd::Constant(e.samples(), 0.01 * (i + 1));
    t.origin = i == 0 ? "transferred (inverse-fir)" : "learned from " + std::to_string(i - 1);
    e.trials.push_back(t);
  }
  const ui::CorrectionOverlay overlay = ui::correction_overlay(e, 2, -1);
  ASSERT_EQ(overlay.series.size(), 3u);
  EXPECT_EQ(overlay.series[0].label, "transferred");
  EXPECT_DOUBLE_EQ(overlay.series[0].values.front(), 0.01);
  e.trials[0].origin = "feedback only";
  EXPECT_EQ(ui::correction_overlay(e, 2, -1).series.size(), 2u);  // only a transferred start is added
}

}  // namespace
}  // namespace bellows
