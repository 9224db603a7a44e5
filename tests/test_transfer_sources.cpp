// Which saved sessions may teach a run: on a rig, only sessions of the same rig profile (another
// profile is another arm, or the same arm wired and calibrated otherwise).
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

}  // namespace
}  // namespace bellows
