// app/device_factory: one device for every command. The [device] section with the command line on
// top, unknown devices and misplaced options refused with one clear line, t7 refused where it is
// not built, and what a session records about the device; the CLI of run, identify, console and
// rig check all take the same options.
#include <gtest/gtest.h>

#include "app/config_file.hpp"
#include "app/device_factory.hpp"
#include "devices/simulated_arm.hpp"
#include "engine/config/configuration.hpp"
#include "engine/base/errors.hpp"
#include "tests/process_runner.hpp"

namespace bellows {
namespace {

TEST(DeviceFactory, TheCommandLineGoesOverTheConfiguration) {
  DeviceParameters configured;
  configured.kind = "lcm";
  configured.lcm_url = "udpm://239.255.76.67:7667?ttl=0";
  EXPECT_EQ(resolve_device({}, configured).kind, "lcm");
  EXPECT_EQ(resolve_device({}, configured).lcm_url, configured.lcm_url);
  const DeviceParameters d = resolve_device({"sim", "", "", ""}, configured);
  EXPECT_EQ(d.kind, "sim");
  EXPECT_EQ(resolve_device({"", "memq://", "", ""}, configured).lcm_url, "memq://");
  EXPECT_EQ(resolve_device({"t7", "", "10.0.0.2", "rig.toml"}, configured).t7_address, "10.0.0.2");
}

TEST(DeviceFactory, UnknownDevicesAndMisplacedOptionsAreRefused) {
  EXPECT_THROW(resolve_device({"usb", "", "", ""}, {}), InputError);
  try {
    resolve_device({"sim", "", "10.0.0.2", ""}, {});
    FAIL() << "--t7 with sim";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--t7 and --rig-profile are for --device t7"), std::string::npos) << e.what();
  }
}

TEST(DeviceFactory, TheDeviceSectionLoadsAndIsChecked) {
  Configuration c;
  apply_config_toml("[device]\nkind = \"lcm\"\nlcm = \"memq://\"\n", "test.toml", c);
  EXPECT_EQ(c.device.kind, "lcm");
  EXPECT_EQ(c.device.lcm_url, "memq://");
  try {
    Configuration bad;
    apply_config_toml("[device]\nkind = \"usb\"\n", "bad.toml", bad);
    FAIL() << "an unknown [device] kind loaded";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("[device] kind"), std::string::npos) << e.what();
  }
  Configuration check;
  apply_config_toml("[rig_check]\nvalve_pulse_s = 0.05\n", "check.toml", check);
  EXPECT_DOUBLE_EQ(check.rig_check.valve_pulse_s, 0.05);
  EXPECT_THROW(apply_config_toml("[rig_check]\nvalve_pulse_s = -1\n", "check.toml", check), InputError);
}

// The configuration layer cannot see the simulated arm's faults; the key's description names them, and
// this keeps it naming every one (a fault added to the arm and not to the description fails here).
TEST(DeviceFactory, PlantFaultsDescriptionNamesEveryFaultTheArmKnows) {
  const ParameterBinding* fault = find_parameter("plant", "fault");
  ASSERT_NE(fault, nullptr);
  EXPECT_EQ(fault->description, "injected fault: " + simulated_fault_names());
  for (const SimulatedFault each : kSimulatedFaults) EXPECT_EQ(simulated_fault_from_string(to_string(each)), each);
  try {
    simulated_fault_from_string("stuck-outlet");
    ADD_FAILURE() << "an unknown fault was accepted";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()), "unknown simulated fault 'stuck-outlet' (" + simulated_fault_names() + ")");
  }
}

TEST(DeviceFactory, TheSimulatedArmRecordsItsSeed) {
  const Configuration c;
  const auto opened = open_device(resolve_device({"sim", "", "", ""}, c.device), c, 42, RealtimeMode::kOff, 0);
  EXPECT_STREQ(opened->device().name(), "sim");
  ASSERT_NE(opened->simulated_arm(), nullptr);
  EXPECT_FALSE(opened->needs_real_time());
  EXPECT_EQ(opened->session_info().at("seed"), 42);
  EXPECT_FALSE(opened->device().health().has_link);
}

TEST(DeviceFactory, AnArmPresetOpensTheSimulatedArmOfSeveralJoints) {
  Configuration c;
  c.arm.preset = "arm3";
  const auto opened = open_device(resolve_device({"sim", "", "", ""}, c.device), c, 7, RealtimeMode::kOff, 0);
  EXPECT_STREQ(opened->device().name(), "sim");
  EXPECT_EQ(opened->simulated_arm(), nullptr) << "not the single-joint arm";
  ASSERT_NE(opened->simulated_arm_chain(), nullptr);
  EXPECT_EQ(opened->simulated_arm_chain()->joints(), 3);
  EXPECT_EQ(opened->device().read_sensors().joint_count, 3);
  EXPECT_FALSE(opened->needs_real_time());
  EXPECT_EQ(opened->session_info().at("seed"), 7);
  EXPECT_EQ(opened->session_info().at("arm"), "arm3");
}

TEST(DeviceFactory, ARigRefusesAnArmOfSeveralJointsInOneLine) {
  Configuration c;
  c.arm.preset = "arm2";
  try {
    open_device(resolve_device({"t7", "", "127.0.0.1:1", ""}, c.device), c, 1, RealtimeMode::kOff, 0);
    FAIL() << "a T7 link must not silently drive one joint of arm2";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(),
                 "[arm] preset = 'arm2': an arm of several joints runs on --device sim or lcm; --device t7 drives one "
                 "joint (leave [arm] out)");
  }
}

TEST(DeviceFactory, AnLcmRigOnAnInProcessBusReportsItsLink) {
  const Configuration c;
  const auto opened = open_device(resolve_device({"lcm", "memq://", "", ""}, c.device), c, 1, RealtimeMode::kOff, 0);
  EXPECT_STREQ(opened->device().name(), "lcm");
  EXPECT_EQ(opened->simulated_arm(), nullptr);
  EXPECT_TRUE(opened->needs_real_time());
  EXPECT_EQ(opened->session_info().at("lcm"), "memq://");
  const DeviceHealth h = opened->device().health();
  EXPECT_TRUE(h.has_link);
  EXPECT_FALSE(h.connected) << "no rig answers on an empty bus";
  std::atomic<bool> stop{false};
  EXPECT_NE(opened->wait_until_served(0.05, stop).find("no rig answered on memq://"), std::string::npos);
  opened->stop();
}

TEST(DeviceFactory, T7WithoutAnAddressIsOneClearLine) {
  const Configuration c;
  try {
    open_device(resolve_device({"t7", "", "", ""}, c.device), c, 1, RealtimeMode::kOff, 0);
    FAIL() << "t7 opened without an address";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "--device t7 needs --t7 HOST[:PORT]");
  }
}

TEST(DeviceFactory, EveryCommandTakesTheSameDeviceOptions) {
  for (const std::string command : {"run --clock wall", "identify", "rig check --yes", "console"}) {
    const auto r = testing::run_process(std::string(BELLOWS_BINARY) + " " + command + " --device usb < /dev/null");
    EXPECT_EQ(r.exit_code, 2) << command;
    EXPECT_NE(r.err.find("--device"), std::string::npos) << command << ": " << r.err;
    const auto misplaced = testing::run_process(std::string(BELLOWS_BINARY) + " " + command +
                                                " --device sim --rig-profile x.toml < /dev/null");
    EXPECT_EQ(misplaced.exit_code, 2) << command;
    EXPECT_NE(misplaced.err.find("--rig-profile are for --device t7"), std::string::npos)
        << command << ": " << misplaced.err;
  }
}

}  // namespace
}  // namespace bellows
