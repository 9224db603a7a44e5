// Which saved sessions may teach a run: on a rig, only sessions of the same rig profile (another
// profile is another arm, or the same arm wired and calibrated otherwise); never a session of another
// arm (a joint count or chain of its own). With one joint the per-joint transfer is the one-joint
// transfer, number for number.
#include <gtest/gtest.h>

#include "app/transfer_sources.hpp"
#include "engine/base/errors.hpp"
#include "session_test_support.hpp"

namespace bellows {
namespace {

Session rig_session(const std::string& profile) {
  Session session = testing::simulate_session(1);
  session.manifest.device = "t7";
  session.manifest.device_info = {{"t7", "127.0.0.1:5020"}, {"rig_profile", profile}};
  return session;
}

TEST(TransferSources, ARigSessionTeachesOnlyRunsWithItsRigProfile) {
  const Configuration config;
  EXPECT_NO_THROW(check_transfer_source(rig_session("paper-rig"), config, "t7", "paper-rig"));
  try {
    check_transfer_source(rig_session("paper-rig"), config, "t7", "lab-b-rig");
    FAIL() << "a session of another rig profile was accepted";
  } catch (const InputError& error) {
    const std::string text = error.what();
    EXPECT_NE(text.find("rig profile 'paper-rig'"), std::string::npos) << text;
    EXPECT_NE(text.find("'lab-b-rig'"), std::string::npos) << text;
  }
  // A session from before profiles were recorded cannot vouch for its rig either.
  Session unknown = rig_session("");
  unknown.manifest.device_info.erase("rig_profile");
  EXPECT_THROW(check_transfer_source(unknown, config, "t7", "paper-rig"), InputError);
  // And the device itself still comes first.
  EXPECT_THROW(check_transfer_source(testing::simulate_session(1), config, "t7", "paper-rig"), InputError);
}

TEST(TransferSources, ASessionOfAnotherArmCannotTeach) {
  const Session session = testing::simulate_session(1);
  Configuration arm2 = session.manifest.configuration;  // the same in all but the arm
  arm2.arm.preset = "arm2";
  try {
    check_transfer_source(session, arm2, session.manifest.device);
    FAIL() << "a one-joint session was accepted for arm2";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("another arm (one joint there, 'arm2' here)"), std::string::npos)
        << error.what();
  }
  Trajectory two = session.trajectory;
  two.angles_rad.push_back(two.joint(0));
  EXPECT_THROW(
      transfer_every_joint({transfer_source_from_session(session)}, arm2.controller, arm2.timing.sample_s(), two),
      InputError)
      << "a source of one joint for a target of two";
}

TEST(TransferSources, WithOneJointTheTransferIsTheOneJointTransferNumberForNumber) {
  const Session session = testing::simulate_session(4);
  const Configuration& config = session.manifest.configuration;
  const JointTransferSource source = transfer_source_from_session(session);
  ASSERT_EQ(source.joints.size(), 1u);
  ASSERT_EQ(source.trials(), 4);
  Trajectory target = session.trajectory;  // a slower copy of the session's: another reference
  target.joint(0) *= 0.7;
  LearningTransfer one;
  one.setup(source.joints, config.controller, config.timing.sample_s());
  const TransferResult direct = one.solve(target);
  const JointTransferResult every = transfer_every_joint({source}, config.controller, config.timing.sample_s(), target);
  ASSERT_EQ(every.joints.size(), 1u);
  EXPECT_EQ(every.joints[0].method, direct.method);
  EXPECT_EQ(every.joints[0].status, direct.status);
  EXPECT_EQ(every.predicted_rms_deg(), direct.predicted_rms_deg);
  EXPECT_EQ(every.predicted_feedback_only_rms_deg(), direct.predicted_feedback_only_rms_deg);
  ASSERT_EQ(every.correction_bar.cols(), 1);
  EXPECT_TRUE(every.correction_bar.col(0) == direct.correction_bar);
}

}  // namespace
}  // namespace bellows
