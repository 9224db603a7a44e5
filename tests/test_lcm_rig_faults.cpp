// The faults a lab meets first on an LCM rig, as processes in a private network namespace (issue
// 25): chambers swapped with the rig's range inside the engine's guard end with the rig's own trip
// named (exit 3, in the JSON and the session), with the range outside the guard with the engine's
// `angle-limit`, never `sensor-stale`; `rig check` passes against io-sim and names the swap against
// `--swapped-chambers`; a clean run reports no link errors (the rig's offers counted apart).
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "tests/lcm_test_support.hpp"
#include "tests/process_runner.hpp"

namespace bellows {
namespace {

using testing::Child;
using testing::kBellows;

nlohmann::json report_of(const Child& child) {
  const std::string out = child.out();
  EXPECT_FALSE(out.empty()) << child.err();
  return out.empty() ? nlohmann::json::object() : nlohmann::json::parse(out);
}

std::string text_of(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

struct RigRun {
  int status = -1;
  nlohmann::json report;
  std::string err;
};

/// io-sim (with `rig_args`, its own `rig_config`) and one `bellows run --device lcm` trial against it.
RigRun run_against_rig(const std::filesystem::path& dir, const std::vector<std::string>& rig_args, const std::string& rig_config,
                       std::vector<std::string> run_args) {
  std::vector<std::string> rig_argv = {kBellows, "io-sim"};
  rig_argv.insert(rig_argv.end(), rig_args.begin(), rig_args.end());
  if (!rig_config.empty()) {
    rig_argv.push_back("--config");
    rig_argv.push_back(rig_config);
  }
  Child rig(rig_argv, dir / "rig.out", dir / "rig.err");
  std::vector<std::string> argv = {kBellows, "run", "--device", "lcm", "--clock", "wall", "--json"};
  argv.insert(argv.end(), run_args.begin(), run_args.end());
  Child run(argv, dir / "run.out", dir / "run.err");
  RigRun result;
  const auto status = run.wait(120.0);
  EXPECT_TRUE(status.has_value()) << "bellows run did not finish";
  rig.signal(SIGTERM);
  EXPECT_TRUE(rig.wait(30.0).has_value());
  result.status = status.value_or(-1);
  result.report = report_of(run);
  result.err = run.err();
  return result;
}

TEST(LcmRigFaults, SwappedChambersInsideTheGuardEndWithTheRigsTripNamed) {
  ENTER_PRIVATE_NETWORK_NAMESPACE_OR_SKIP();
  const auto dir = testing::make_temp_dir("bellows-lcm-swapped");
  setenv("XDG_DATA_HOME", (dir / "xdg").c_str(), 1);
  // The lab's rig stops at 90 deg (its hardware's stops), inside the engine's guard of 95 deg. A
  // build beside the suite may stall threads: not this test's subject (nor a rig timeout).
  const std::string rig_config =
      testing::write_file(dir, "rig.toml", "[trajectory]\nmax_abs_angle_deg = 80\n[safety]\nangle_limit_deg = 85\nmissed_deadline_streak = 1000\n[lcm]\nrig_angle_limit_deg = 90\nrig_timeout_s = 2.0\n").string();
  const RigRun r = run_against_rig(dir, {"--swapped-chambers"}, rig_config, {"--iterations", "0", "--name", "swapped"});
  EXPECT_EQ(r.status, 3) << r.err;
  EXPECT_EQ(r.report["fault"]["name"], "rig-limit") << r.report.dump();
  const std::string message = r.report["fault"]["message"].get<std::string>();
  EXPECT_NE(message.find("the rig stopped joint 1 at"), std::string::npos) << message;
  EXPECT_NE(message.find("check the chamber wiring"), std::string::npos) << message;
  EXPECT_NE(r.err.find("rig-limit"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("sensor-stale"), std::string::npos) << r.err;
  EXPECT_GT(r.report["lcm"]["rig"]["rig_fault_states"].get<int>(), 0);
  EXPECT_NE(r.report["lcm"]["rig"]["last_fault_bits"].get<int>() & 32, 0) << "FAULT_ANGLE_LIMIT";
  // The session's fault event names it too.
  ASSERT_TRUE(r.report["session"].is_string()) << r.report.dump();
  const std::string manifest = text_of(std::filesystem::path(r.report["session"].get<std::string>()) / "manifest.json");
  EXPECT_NE(manifest.find("rig-limit"), std::string::npos) << manifest.substr(0, 2000);
  EXPECT_NE(manifest.find("the rig stopped joint 1"), std::string::npos);
}

TEST(LcmRigFaults, SwappedChambersWithTheRigsRangeOutsideTheGuardEndWithTheEnginesAngleLimit) {
  ENTER_PRIVATE_NETWORK_NAMESPACE_OR_SKIP();
  const auto dir = testing::make_temp_dir("bellows-lcm-swapped-wide");
  // The rig's default range (100 deg) outside the engine's guard (95); its command timeout loaded-machine.
  const std::string rig_config = testing::write_file(dir, "rig.toml", "[lcm]\nrig_timeout_s = 2.0\n").string();
  const RigRun r = run_against_rig(dir, {"--swapped-chambers"}, rig_config, {"--iterations", "0", "--no-save"});
  EXPECT_EQ(r.status, 3) << r.err;
  EXPECT_EQ(r.report["fault"]["name"], "angle-limit") << r.report.dump();
  EXPECT_EQ(r.err.find("sensor-stale"), std::string::npos) << r.err;
}

TEST(LcmRigFaults, ACleanRunReportsNoLinkErrorsAndCountsTheOffersApart) {
  ENTER_PRIVATE_NETWORK_NAMESPACE_OR_SKIP();
  const auto dir = testing::make_temp_dir("bellows-lcm-clean");
  // The machine's stalls are not this test's subject: ride-through, the stale limit and the rig's
  // command timeout have theirs.
  const std::string config = testing::write_file(dir, "tolerant.toml", "[safety]\nmissed_deadline_streak = 1000\n[lcm]\nrig_timeout_s = 2.0\n").string();
  const RigRun r = run_against_rig(dir, {}, config, {"--iterations", "0", "--no-save", "--config", config});
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json& rig = r.report["lcm"]["rig"];
  EXPECT_GT(rig["states"]["offers"].get<int>(), 0) << "the rig's offers before binding";
  EXPECT_EQ(rig["states"]["ignored"]["foreign"], 0) << rig.dump();
  EXPECT_EQ(r.report["loop"]["link"]["errors"], 0) << r.report["loop"].dump();
  EXPECT_EQ(r.report["iterations"][0]["held_samples"].get<int>() >= 0, true);
}

TEST(LcmRigFaults, RigCheckPassesAgainstIoSimAndNamesTheSwapAgainstSwappedChambers) {
  ENTER_PRIVATE_NETWORK_NAMESPACE_OR_SKIP();
  const auto dir = testing::make_temp_dir("bellows-lcm-rig-check");
  const std::string config = testing::write_file(dir, "tolerant.toml", "[safety]\nmissed_deadline_streak = 1000\n[lcm]\nrig_timeout_s = 2.0\n").string();
  for (const bool swapped : {false, true}) {
    std::vector<std::string> rig_argv = {kBellows, "io-sim", "--config", config};
    if (swapped) rig_argv.push_back("--swapped-chambers");
    Child rig(rig_argv, dir / "rig.out", dir / "rig.err");
    Child check({kBellows, "rig", "check", "--device", "lcm", "--yes", "--json", "--no-save", "--config", config},
                dir / "check.out", dir / "check.err");
    const auto status = check.wait(120.0);
    rig.signal(SIGTERM);
    ASSERT_TRUE(rig.wait(30.0).has_value());
    ASSERT_TRUE(status.has_value()) << "rig check did not finish";
    const nlohmann::json report = report_of(check);
    if (!swapped) {
      EXPECT_EQ(*status, 0) << check.err();
      EXPECT_EQ(report["all_pass"], true) << report.dump();
    } else {
      EXPECT_NE(*status, 0) << check.err();
      EXPECT_EQ(report["all_pass"], false);
      EXPECT_NE(check.err().find("are swapped"), std::string::npos) << check.err();
    }
  }
}

}  // namespace
}  // namespace bellows
