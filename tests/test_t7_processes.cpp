// `bellows t7-sim` and `bellows run --device t7` as separate processes on 127.0.0.1: learning on the
// T7 path matches the in-process arm; a kill -9'd bellows leaves safe valves behind (the T7's
// watchdog); SIGTERM vents at once; t7-sim stopped mid-trial faults the run naming the link; a bad
// rig profile or an unreachable address is one line and no session.
#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <fstream>
#include <thread>
#include <numbers>
#include <sstream>

#include <nlohmann/json.hpp>

#include "engine/config/configuration.hpp"
#include "tests/lcm_test_support.hpp"
#include "tests/process_runner.hpp"

namespace bellows {
namespace {

using testing::Child;

using testing::kBellows;

/// A loopback port that was free a moment ago.
int free_port() {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof address);
  socklen_t length = sizeof address;
  getsockname(fd, reinterpret_cast<sockaddr*>(&address), &length);
  close(fd);
  return ntohs(address.sin_port);
}

class T7Processes : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::make_temp_dir("bellows-t7");
    setenv("XDG_DATA_HOME", (dir_ / "xdg").c_str(), 1);
    port_ = free_port();
    address_ = "127.0.0.1:" + std::to_string(port_);
    status_ = dir_ / "status.json";
  }

  std::unique_ptr<Child> start_sim(std::vector<std::string> drills = {}) {
    std::vector<std::string> argv = {kBellows, "t7-sim", "--listen", address_, "--status", status_.string()};
    argv.insert(argv.end(), drills.begin(), drills.end());
    auto sim = std::make_unique<Child>(argv, dir_ / "sim.out", dir_ / "sim.err");
    EXPECT_TRUE(wait_for([&] { return std::filesystem::exists(status_); })) << sim->err();
    return sim;
  }

  /// The runs tolerate a loaded test machine's scheduling (CI runs tests two at a time beside
  /// builds): a 0.5 s answer, a 0.5 s command timeout of the link, 400 stale ticks, long missed-deadline streaks. The
  /// guards have their own tests; the link's timing is the benchmark's business (bench/t7_round_trip.sh).
  std::unique_ptr<Child> start_run(int iterations, const std::string& name) {
    const std::filesystem::path config =
        testing::write_file(dir_, "loaded.toml",
                            "[t7]\nresponse_timeout_s = 0.5\ncommand_timeout_s = 0.5\n[safety]\nstale_ticks = "
                            "400\nmissed_deadline_streak = 100000\n");
    return std::make_unique<Child>(std::vector<std::string>{kBellows, "run", "--device", "t7", "--t7", address_, "--rt",
                                                            "try",  // a rig: the wall clock
                                                            "--config", config.string(), "--iterations",
                                                            std::to_string(iterations), "--json", "--no-save"},
                                   dir_ / (name + ".out"), dir_ / (name + ".err"));
  }

  /// `bellows run` of 3 iterations against a t7-sim whose answers will trickle: [t7] response_timeout_s
  /// as given, 100 stale ticks (0.5 s), long missed-deadline streaks (a loaded machine's stalls before
  /// the trickle must not end the run first: at 4 ms and 40 ticks, CI's load faulted it before the drill).
  std::unique_ptr<Child> start_trickled_run(const std::string& response_timeout_s) {
    const std::filesystem::path config =
        testing::write_file(dir_, "trickle.toml",
                            "[t7]\nresponse_timeout_s = " + response_timeout_s +
                                "\n[safety]\nstale_ticks = 100\nmissed_deadline_streak = 100000\n");
    return std::make_unique<Child>(
        std::vector<std::string>{kBellows, "run", "--device", "t7", "--t7", address_, "--rt", "try", "--config",
                                 config.string(), "--iterations", "3", "--json", "--no-save"},
        dir_ / "run.out", dir_ / "run.err");
  }
  /// Until `sim` says its answers trickle; false (and why) when it never does.
  ::testing::AssertionResult trickle_began(Child& sim, Child& run) {
    if (wait_for([&] { return sim.out().find("answers trickle from now on") != std::string::npos; }))
      return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure() << sim.out() << "\nbellows run: " << run.err();
  }

  /// Runs bellows with `args` to the end (sessions into this test's XDG_DATA_HOME).
  testing::ProcessResult run_cli(const std::vector<std::string>& args) {
    std::vector<std::string> argv = {kBellows};
    argv.insert(argv.end(), args.begin(), args.end());
    Child child(argv, dir_ / "cli.out", dir_ / "cli.err");
    testing::ProcessResult r;
    r.exit_code = child.wait(60.0).value_or(-1);
    r.out = child.out();
    r.err = child.err();
    return r;
  }

  bool no_session_saved() const {
    return !std::filesystem::exists(dir_ / "xdg" / "bellows" / "sessions") ||
           std::filesystem::is_empty(dir_ / "xdg" / "bellows" / "sessions");
  }

  nlohmann::json status() const {
    std::ifstream in(status_);
    std::stringstream text;
    text << in.rdbuf();
    return text.str().empty() ? nlohmann::json::object() : nlohmann::json::parse(text.str());
  }

  /// Polls for up to 30 s: a generous bound for a loaded machine (no timing is asserted by it).
  static bool wait_for(const std::function<bool()>& done) {
    for (int i = 0; i < 3000; ++i) {
      if (done()) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return done();
  }

  /// Waits until a trial runs: t7-sim's lines show an inlet opening.
  bool wait_for_trial() {
    return wait_for([&] {
      const nlohmann::json s = status();
      return s.contains("valves") &&
             (s["valves"]["inlet_a"].get<double>() > 0.0 || s["valves"]["inlet_b"].get<double>() > 0.0);
    });
  }

  std::filesystem::path dir_, status_;
  int port_ = 0;
  std::string address_;
};

std::vector<double> rms_of(const nlohmann::json& report) {
  std::vector<double> rms;
  for (const auto& it : report.at("iterations")) rms.push_back(it.at("rms_deg").get<double>());
  return rms;
}

TEST_F(T7Processes, LearningThroughAT7MatchesTheInProcessArm) {
  auto sim = start_sim();
  auto run = start_run(1, "run");
  ASSERT_EQ(run->wait(120.0), 0) << run->err();
  const nlohmann::json t7 = nlohmann::json::parse(run->out());
  const testing::ProcessResult local = testing::run_process(
      kBellows + " run --iterations 1 --json --no-save --seed 1 --config " + (dir_ / "loaded.toml").string());
  ASSERT_EQ(local.exit_code, 0) << local.err;
  const std::vector<double> remote_rms = rms_of(t7), local_rms = rms_of(nlohmann::json::parse(local.out));
  ASSERT_EQ(remote_rms.size(), 2u);
  ASSERT_EQ(local_rms.size(), 2u);
  // Feedback alone tracks through the T7 as in process. What the learning makes of it depends on the
  // host too: a tick whose answer came late is held (error 0, not learned from), and a loaded test
  // machine holds tens of them (18-29 % off at iteration 1 beside builds). So the learned iteration
  // must show the learning acting through the T7 (at least half the in-process gain), not the figure
  // a quiet machine gives: that one, every iteration within 15 %, is bench/rig_links.sh's
  // (docs/benchmarks.md).
  const nlohmann::json& held = t7.at("loop").at("held_ticks");
  EXPECT_NEAR(remote_rms[0], local_rms[0], 0.15 * local_rms[0]) << "held ticks: " << held;
  EXPECT_LT(remote_rms[1], remote_rms[0] - 0.5 * (local_rms[0] - local_rms[1]))
      << "through the T7: " << remote_rms[0] << " -> " << remote_rms[1] << " deg, in process " << local_rms[0] << " -> "
      << local_rms[1] << "; held ticks: " << held;
  EXPECT_EQ(t7.at("device"), "t7");
  EXPECT_EQ(t7.at("clock"), "wall");                        // no --clock: a rig runs on the wall clock
  EXPECT_EQ(t7.at("model").at("source"), "configuration");  // the built-in profile has no [model]
  EXPECT_EQ(t7.at("model").at("kappa_rad_per_bar"), Configuration{}.model.kappa_rad_per_bar);
  const nlohmann::json link = t7.at("loop").at("link");
  EXPECT_GT(link.at("exchanges").get<std::uint64_t>(), 1000u);
  // A loaded test machine can hold a request past even the 0.5 s timeout; the link recovers by
  // itself (T7Loopback.ALateAnswerIsDroppedAndTheLinkAnswersAgain) and the learning above matched.
  EXPECT_LE(link.at("errors").get<std::uint64_t>() * 100, link.at("exchanges").get<std::uint64_t>());
  EXPECT_GT(link.at("round_trip_ms").at("max").get<double>(), 0.0);
  // bellows vented on its way out: the lines were safe before the silence began.
  const nlohmann::json s = status();
  EXPECT_TRUE(s.at("safe").get<bool>());
  EXPECT_LE(s.at("safe_since_s").get<double>(), s.at("last_request_s").get<double>());
  // The strict T7-Pro refused nothing of the whole session, and held one connection at a time.
  EXPECT_EQ(s.at("refusals").get<int>(), 0) << sim->out();
  EXPECT_EQ(s.at("exceptions").get<int>(), 0) << sim->out();
  EXPECT_EQ(s.at("max_clients").get<int>(), 1) << sim->out();
  EXPECT_EQ(sim->out().find("refused"), std::string::npos) << sim->out();
}

// The T7's watchdog is the device's own timing; what this shows is that bellows armed it so that a
// killed bellows leaves the lines safe through it.
TEST_F(T7Processes, AKilledBellowsLeavesSafeValvesWithinTheWatchdogTimeoutAndAPwmPeriod) {
  auto sim = start_sim();
  auto run = start_run(2, "run");
  ASSERT_TRUE(wait_for_trial()) << run->err();
  run->signal(SIGKILL);
  ASSERT_EQ(run->wait(10.0), 128 + SIGKILL);
  ASSERT_TRUE(wait_for([&] { return status().at("watchdog").at("actions").get<int>() > 0; })) << sim->out();
  const nlohmann::json s = status();
  EXPECT_TRUE(s.at("safe").get<bool>()) << s.dump();
  // The watchdog acted after its timeout of silence (no earlier: it was the watchdog), and the lines
  // were safe within a PWM period of its action. How soon after the timeout t7-sim's thread notices it
  // is its host's scheduling (seconds on a loaded machine), not what a T7 or bellows does.
  // The first action of this silence: while it lasts the watchdog acts again every timeout, and
  // on a loaded machine the test may read the status only after several.
  const double action_s = s.at("watchdog").at("first_action_s").get<double>();
  const double safe_since_s = s.at("safe_since_s").get<double>();
  EXPECT_GE(action_s - s.at("last_request_s").get<double>(), s.at("watchdog").at("timeout_s").get<double>())
      << s.dump();
  EXPECT_GE(safe_since_s, action_s) << s.dump();
  EXPECT_LE(safe_since_s - action_s, s.at("pwm_period_s").get<double>()) << s.dump();
  EXPECT_NE(sim->out().find("watchdog"), std::string::npos);
}

TEST_F(T7Processes, SigtermVentsAtOnceByItself) {
  auto sim = start_sim();
  auto run = start_run(2, "run");
  ASSERT_TRUE(wait_for_trial()) << run->err();
  run->signal(SIGTERM);
  ASSERT_EQ(run->wait(10.0), 128 + SIGTERM) << run->err();
  const nlohmann::json s = status();
  EXPECT_TRUE(s.at("safe").get<bool>());
  // Safe through bellows' own last request, not through the watchdog after the silence.
  EXPECT_LE(s.at("safe_since_s").get<double>(), s.at("last_request_s").get<double>()) << s.dump();
}

TEST_F(T7Processes, T7SimStoppedMidTrialFaultsTheRunNamingTheLink) {
  auto sim = start_sim();
  auto run = start_run(2, "run");
  ASSERT_TRUE(wait_for_trial()) << run->err();
  sim->signal(SIGKILL);
  ASSERT_EQ(run->wait(30.0), 3) << run->err();
  const std::string err = run->err();
  // A dead link is named for what it is (issue 25): link-lost, naming the T7's address; never sensor-stale.
  EXPECT_NE(err.find("link-lost"), std::string::npos) << err;
  EXPECT_EQ(err.find("sensor-stale"), std::string::npos) << err;
  EXPECT_NE(err.find("the T7 at " + address_), std::string::npos) << err;
  const nlohmann::json report = nlohmann::json::parse(run->out());
  EXPECT_EQ(report.at("fault").at("name"), "link-lost");
  EXPECT_NE(report.at("fault").at("message").get<std::string>().find(address_), std::string::npos) << report.dump();
}

// A link that trickles (one byte of each answer every 0.4 s, within libmodbus' default byte
// timeout): the exchange's one deadline ends each wait after [t7] response_timeout_s (0.1 s here,
// a whole answer takes seconds), so the run
// faults and vents within the stale limit and one response timeout, not seconds later.
TEST_F(T7Processes, ATricklingLinkEndsTheRunVentedWithinTheStaleLimitAndOneResponseTimeout) {
  auto sim = start_sim({"--trickle-after", "1.5"});
  auto run = start_trickled_run("0.1");
  ASSERT_TRUE(trickle_began(*sim, *run));
  const auto trickle = std::chrono::steady_clock::now();
  ASSERT_EQ(run->wait(30.0), 3) << run->err();
  const double after_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - trickle).count();
  // 100 ticks (0.5 s) + 0.1 s, with room for a loaded machine's scheduling; before: 12 s and more.
  // (A loaded machine's stalls before the trickle must not end the run first: at 4 ms and 40 ticks,
  // CI's load faulted it link-lost before the drill began.)
  EXPECT_LT(after_s, 2.0) << run->err();
  const nlohmann::json report = nlohmann::json::parse(run->out());
  EXPECT_TRUE(report.contains("fault")) << run->out();
}

// A T7 whose answers all come, each after its deadline (one byte every 2 ms: a whole answer takes tens
// of ms against a 20 ms deadline): the run faults, named for what happened, sensor-stale "answers, but
// late"; never link-lost, which tells the operator to check the T7's power and cable.
TEST_F(T7Processes, AT7ThatAnswersLateIsNamedLateNotLost) {
  auto sim = start_sim({"--trickle-after", "1.5", "--trickle-byte-s", "0.002"});
  auto run = start_trickled_run("0.02");
  ASSERT_TRUE(trickle_began(*sim, *run));
  ASSERT_EQ(run->wait(30.0), 3) << run->err();
  const nlohmann::json report = nlohmann::json::parse(run->out());
  EXPECT_EQ(report.at("fault").at("name"), "sensor-stale") << report.dump();
  EXPECT_NE(report.at("fault").at("message").get<std::string>().find("the T7 at " + address_ + " answers, but late"),
            std::string::npos)
      << report.dump();
  EXPECT_EQ(run->err().find("link-lost"), std::string::npos) << run->err();
}

// SIGINT 3 s into connecting to a device that answers each request after 1.5 s: the command ends at
// once, 128 + SIGINT, nothing armed; without the signal the connect gives up within
// [t7] connect_timeout_s + 1 s, in one line naming the address.
TEST_F(T7Processes, ConnectingIsBoundedAndEndsAtOnceOnSigint) {
  auto sim = start_sim({"--answer-after", "1.5"});
  const std::filesystem::path patient = testing::write_file(dir_, "patient.toml", "[t7]\nconnect_timeout_s = 60\n");
  Child check({kBellows, "rig", "check", "--device", "t7", "--t7", address_, "--config", patient.string(), "--no-save"},
              dir_ / "check.out", dir_ / "check.err");
  std::this_thread::sleep_for(std::chrono::seconds(3));
  const auto signalled = std::chrono::steady_clock::now();
  check.signal(SIGINT);
  EXPECT_EQ(check.wait(10.0), 128 + SIGINT) << check.err();
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - signalled).count(), 1.0);
  EXPECT_EQ(status().at("valves").at("inlet_a").get<double>(), 0.0) << "nothing armed";
  EXPECT_EQ(status().at("valves").at("inlet_b").get<double>(), 0.0);

  const std::filesystem::path bounded = testing::write_file(dir_, "bounded.toml", "[t7]\nconnect_timeout_s = 2\n");
  const auto start = std::chrono::steady_clock::now();
  const testing::ProcessResult r =
      run_cli({"rig", "check", "--device", "t7", "--t7", address_, "--config", bounded.string(), "--no-save"});
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 2.0 + 1.0);
  EXPECT_EQ(r.exit_code, 4) << r.err;
  EXPECT_NE(r.err.find("t7 " + address_ + ": no answer within [t7] connect_timeout_s = 2 s"), std::string::npos)
      << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_TRUE(no_session_saved());
}

// A T7 that connects but never answers a read: `rig check` says there is no reading and fails (it
// printed zeros and exited 0).
TEST_F(T7Processes, RigCheckWithoutAReadingSaysSoAndFails) {
  auto sim = start_sim({"--silent-reads"});
  const testing::ProcessResult r = run_cli({"rig", "check", "--device", "t7", "--t7", address_, "--no-save"});
  EXPECT_EQ(r.exit_code, 4) << r.out << r.err;
  EXPECT_NE(r.err.find("no reading from the T7 at " + address_), std::string::npos) << r.err;
  EXPECT_EQ(r.out.find("0.0000 V"), std::string::npos) << r.out;
}

// On the loaded machine's timing (as the runs: start_run): the default 4 ms exchange deadline and 3
// stale ticks fault a check on a 2-core machine running the suite (the ride-through is the
// engine's, issue 22); what is checked here is that the strict T7-Pro accepts every request. The
// pulses are 0.1 s, not 30 ms: a stalled tick of a loaded host can eat most of a 30 ms pulse, and
// then a good valve reads as dead (about 1 run in 7 under the suite's load); the fill before an outlet's
// test likewise (CI, 2026-12-02: a 30 ms fill left chamber B 0.01 bar above ambient: outlet B untested).
// A stalled tick also lengthens a fill (t7-sim's arm runs on the wall clock, as a rig's air does): CI,
// 2026-12-05, a 0.1 s fill that lasted about twice that took chamber B past p_max + margin (1.65 bar)
// and the engine vented, rightly. p_max_bar 2.8 puts the limit (3.05 bar) above the 3 bar supply.
TEST_F(T7Processes, RigCheckPassesEveryValveOnTheStrictT7Pro) {
  auto sim = start_sim();
  const std::filesystem::path config =
      testing::write_file(dir_, "loaded.toml",
                          "[t7]\nresponse_timeout_s = 0.5\ncommand_timeout_s = 0.5\n[safety]\nstale_ticks = "
                          "400\nmissed_deadline_streak = 100000\n[controller]\np_max_bar = 2.8\n"
                          "[rig_check]\nvalve_pulse_s = 0.1\nfill_s = 0.1\n");
  const testing::ProcessResult r =
      run_cli({"rig", "check", "--device", "t7", "--t7", address_, "--config", config.string(), "--no-save", "--yes"});
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("rig check: every valve passed"), std::string::npos) << r.out;
  EXPECT_EQ(status().at("refusals").get<int>(), 0) << sim->out();
  EXPECT_EQ(status().at("max_clients").get<int>(), 1) << sim->out();
}

// Mid-run, another program halves clock 0's roll value: the T7 refuses bellows' wide duty cycles
// (LabJack error 2565). The run faults, and what it says names the register and LabJack's error,
// not only a stale reading.
TEST_F(T7Processes, AModbusExceptionDuringARunNamesTheRegisterAndLabJacksError) {
  auto sim = start_sim({"--halve-roll-after", "2"});
  auto run = start_run(2, "run");
  ASSERT_EQ(run->wait(60.0), 3) << run->err();
  const std::string err = run->err();
  EXPECT_NE(err.find("_EF_CONFIG_A"), std::string::npos) << err;
  EXPECT_NE(err.find("LabJack error 2565 EF_VALUE_GREATER_THAN_PERIOD"), std::string::npos) << err;
  EXPECT_NE(sim->out().find("LabJack error 2565"), std::string::npos) << sim->out();
}

TEST_F(T7Processes, ASilentLinkFaultsTheRunAndTheWatchdogVents) {
  auto sim = start_sim({"--silent-after", "3"});
  auto run = start_run(2, "run");
  ASSERT_EQ(run->wait(60.0), 3) << run->err();
  // A T7 that answers nothing is a lost link, named with its address (issue 25), not a stale sensor.
  EXPECT_NE(run->err().find("link-lost"), std::string::npos) << run->err();
  EXPECT_NE(run->err().find("the T7 at " + address_), std::string::npos) << run->err();
  ASSERT_TRUE(wait_for([&] { return status().at("watchdog").at("actions").get<int>() > 0; }));
  EXPECT_TRUE(status().at("safe").get<bool>());
}

std::string text_of(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string paper_profile_text() {
  return text_of(std::filesystem::path(BELLOWS_SOURCE_DIR) / "profiles" / "paper-rig.toml");
}

// The first day's identification on a T7 (t7-sim): the trials run through the rig, the fit goes into
// the rig profile's [model], and all of it is recorded in a session (the device with its address and
// rig profile, the identification trial as iteration 0, the fit, what was written where).
TEST_F(T7Processes, IdentifyOnAT7StoresTheModelInTheProfileAndRecordsASession) {
  const std::filesystem::path profile = testing::write_file(dir_, "my-rig.toml", paper_profile_text());
  const std::filesystem::path config =
      testing::write_file(dir_, "identify.toml",
                          "[identify]\nduration_s = 6.0\n[t7]\nresponse_timeout_s = 0.5\ncommand_timeout_s = "
                          "0.5\n[safety]\nstale_ticks = 400\nmissed_deadline_streak = 100000\n");
  auto sim = start_sim();
  const testing::ProcessResult r =
      run_cli({"identify", "--device", "t7", "--t7", address_, "--rig-profile", profile.string(), "--rt", "try",
               "--config", config.string(), "--write-model", profile.string(), "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json report = nlohmann::json::parse(r.out);
  EXPECT_EQ(report["written_as"], "rig_profile");
  ASSERT_TRUE(report["session"].is_string()) << r.out;
  EXPECT_NE(text_of(profile).find("# fitted by bellows identify"), std::string::npos);

  const testing::ProcessResult shown = run_cli({"sessions", "show", "--json", report["session"].get<std::string>()});
  ASSERT_EQ(shown.exit_code, 0) << shown.err;
  const nlohmann::json session = nlohmann::json::parse(shown.out);
  EXPECT_EQ(session["device"], "t7");
  EXPECT_EQ(session["device_info"]["t7"], address_);
  EXPECT_EQ(session["device_info"]["rig_profile"], "paper-rig");
  EXPECT_EQ(session["iterations"].size(), 1u);
  bool fitted = false, written = false;
  for (const nlohmann::json& e : session["events"]) {
    fitted = fitted || e["kind"] == "identify-fit";
    written = written ||
              (e["kind"] == "model-written" &&
               e["message"].get<std::string>().find("into the rig profile " + profile.string()) != std::string::npos);
  }
  EXPECT_TRUE(fitted) << session["events"];
  EXPECT_TRUE(written) << session["events"];
}

// A rig profile with an identified [model]: `bellows run` learns with it, and its session says so
// (the configuration records the model, `model.source` where it came from). A run without one uses
// the configuration's (LearningThroughAT7MatchesTheInProcessArm).
TEST_F(T7Processes, RunLearnsWithTheRigProfilesIdentifiedModel) {
  std::string text = paper_profile_text();
  const std::string name_line = "name = \"paper-rig\"";
  ASSERT_NE(text.find(name_line), std::string::npos);
  text.replace(text.find(name_line), name_line.size(), "name = \"bench-rig\"");
  text += "\n[model]\nkappa_rad_per_bar = 6.5\nomega0_rad_per_s = 12.0\ndamping = 0.4\n";
  const std::filesystem::path profile = testing::write_file(dir_, "bench-rig.toml", text);
  const std::filesystem::path config =
      testing::write_file(dir_, "loaded.toml",
                          "[t7]\nresponse_timeout_s = 0.5\ncommand_timeout_s = 0.5\n[safety]\nstale_ticks = "
                          "400\nmissed_deadline_streak = 100000\n");
  auto sim = start_sim();
  const testing::ProcessResult r =
      run_cli({"run", "--device", "t7", "--t7", address_, "--rig-profile", profile.string(), "--rt", "try", "--config",
               config.string(), "--iterations", "0", "--json", "--data-dir", (dir_ / "data").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json report = nlohmann::json::parse(r.out);
  EXPECT_EQ(report["model"]["source"], "rig_profile");
  EXPECT_EQ(report["model"]["rig_profile"], "bench-rig");
  EXPECT_EQ(report["model"]["kappa_rad_per_bar"], 6.5);
  EXPECT_EQ(report["model"]["omega0_rad_per_s"], 12.0);
  EXPECT_EQ(report["model"]["damping"], 0.4);
  const nlohmann::json manifest =
      nlohmann::json::parse(text_of(std::filesystem::path(report["session"].get<std::string>()) / "manifest.json"));
  EXPECT_EQ(manifest["model"]["source"], "rig_profile");
  EXPECT_EQ(manifest["model"]["kappa_rad_per_bar"], 6.5);
  EXPECT_EQ(manifest["configuration"]["model"]["kappa"], 6.5);
  EXPECT_EQ(manifest["configuration"]["model"]["omega0"], 12.0);
  EXPECT_EQ(manifest["device_info"]["rig_profile"], "bench-rig");
  const testing::ProcessResult shown = run_cli({"sessions", "show", report["session"].get<std::string>()});
  ASSERT_EQ(shown.exit_code, 0) << shown.err;
  EXPECT_NE(shown.out.find("model        kappa 6.5 rad/bar, omega0 12 1/s, damping 0.4 (from the rig_profile)"),
            std::string::npos)
      << shown.out;
}

// Zeroing the angle headless: the profile bellows reads says the zero is 0.1 rad off (t7-sim's arm
// hangs at its true zero), so the arm reads about -5.7 deg; after `rig check --zero-angle` the
// file's zero is where the arm is, and the next check reads about 0 deg. No valve opened.
TEST_F(T7Processes, ZeroingTheAngleWritesTheProfileAndTheArmThenReadsZero) {
  auto sim = start_sim();
  std::string text = paper_profile_text();
  const std::string zero_line = "angle_zero_rad = 0.0";
  ASSERT_NE(text.find(zero_line), std::string::npos);
  text.replace(text.find(zero_line), zero_line.size(), "angle_zero_rad = 0.1");
  const std::filesystem::path profile = testing::write_file(dir_, "my-rig.toml", text);
  const std::vector<std::string> device = {"--device",       "t7",   "--t7", address_, "--rig-profile",
                                           profile.string(), "--rt", "off"};
  std::vector<std::string> zero = {"rig", "check", "--zero-angle", "--json"};
  zero.insert(zero.end(), device.begin(), device.end());
  const testing::ProcessResult r = run_cli(zero);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json report = nlohmann::json::parse(r.out);
  EXPECT_NEAR(report["angle_zero"]["read_deg"].get<double>(), -0.1 * 180.0 / std::numbers::pi, 1.0);
  EXPECT_NEAR(report["angle_zero"]["angle_zero_rad"].get<double>(), 0.0, 0.02);
  const std::string written = text_of(profile);
  EXPECT_NE(written.find("# zeroed by bellows"), std::string::npos) << written;
  EXPECT_NE(written.find("# The model identified on this rig"), std::string::npos) << "the comments stay";
  EXPECT_EQ(status()["valves"]["inlet_a"].get<double>(), 0.0) << "no valve opened";

  std::vector<std::string> look = {"rig", "check", "--inputs-only", "--json"};
  look.insert(look.end(), device.begin(), device.end());
  const testing::ProcessResult after = run_cli(look);
  ASSERT_EQ(after.exit_code, 0) << after.err;
  EXPECT_NEAR(nlohmann::json::parse(after.out)["reading"]["angle_deg"].get<double>(), 0.0, 1.0);

  // The built-in profile has no file to write: one line, exit 2.
  const testing::ProcessResult builtin =
      run_cli({"rig", "check", "--zero-angle", "--device", "t7", "--t7", address_, "--rt", "off"});
  EXPECT_EQ(builtin.exit_code, 2);
  EXPECT_NE(builtin.err.find("--rig-profile FILE"), std::string::npos) << builtin.err;
}

// A late answer mid-zeroing (t7-sim's stall drill; CI's loaded machine met one): the link drops the
// answers that came late and answers again, and the zeroing goes on to write the profile.
TEST_F(T7Processes, ZeroingRidesOutALateAnswer) {
  auto sim = start_sim({"--stall-after", "0.3", "--stall-s", "0.2"});
  const std::filesystem::path profile = testing::write_file(dir_, "my-rig.toml", paper_profile_text());
  const std::filesystem::path config =
      testing::write_file(dir_, "slow-zero.toml", "[rig_check]\nzero_readings = 200\n");
  const testing::ProcessResult r =
      run_cli({"rig", "check", "--zero-angle", "--json", "--device", "t7", "--t7", address_, "--rig-profile",
               profile.string(), "--rt", "off", "--config", config.string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["angle_zero"]["readings"], 200);
  EXPECT_NE(r.err.find("answers again"), std::string::npos) << r.err;
  EXPECT_NE(text_of(profile).find("# zeroed by bellows"), std::string::npos);
  EXPECT_EQ(status()["stalls"], 1);
}

// A link that falls silent mid-zeroing ends it after [t7] connect_timeout_s without a fresh
// reading: one line, exit 4, the profile as it was (it used to wait for ever).
TEST_F(T7Processes, ZeroingEndsWhenTheLinkFallsSilentAndLeavesTheProfile) {
  // Silent after 3 s: the connect and configuration (some 90 requests at a T7's pace, on a loaded
  // machine) are done by then, within their 2.5 s.
  auto sim = start_sim({"--silent-after", "3"});
  const std::string text = paper_profile_text();
  const std::filesystem::path profile = testing::write_file(dir_, "my-rig.toml", text);
  const std::filesystem::path config = testing::write_file(
      dir_, "endless-zero.toml", "[rig_check]\nzero_readings = 1000000\n[t7]\nconnect_timeout_s = 2.5\n");
  const testing::ProcessResult r =
      run_cli({"rig", "check", "--zero-angle", "--device", "t7", "--t7", address_, "--rig-profile", profile.string(),
               "--rt", "off", "--config", config.string()});
  EXPECT_EQ(r.exit_code, 4) << r.err;
  EXPECT_NE(r.err.find("--zero-angle: no fresh reading from " + address_ + " for 2.5 s"), std::string::npos) << r.err;
  EXPECT_EQ(text_of(profile), text);
}

// `identify --write-model PROFILE`: a rig profile (it has [valves]) gets the fit in its [model],
// which the profile then carries (the simulated arm's identification: the file path is the same
// for every device).
TEST_F(T7Processes, IdentifyWritesTheModelIntoARigProfile) {
  const std::filesystem::path profile = testing::write_file(dir_, "rig.toml", paper_profile_text());
  const testing::ProcessResult r =
      run_cli({"identify", "--device", "sim", "--write-model", profile.string(), "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json report = nlohmann::json::parse(r.out);
  EXPECT_EQ(report["written_as"], "rig_profile");
  const std::string written = text_of(profile);
  EXPECT_NE(written.find("[model]\nkappa_rad_per_bar = "), std::string::npos) << written;
  EXPECT_NE(written.find("# fitted by bellows identify"), std::string::npos) << written;
  // The profile with its model is valid: a rig check on it reads it.
  auto sim = start_sim();
  const testing::ProcessResult check = run_cli({"rig", "check", "--inputs-only", "--device", "t7", "--t7", address_,
                                                "--rig-profile", profile.string(), "--rt", "off"});
  EXPECT_EQ(check.exit_code, 0) << check.err;
}

TEST_F(T7Processes, ABadRigProfileIsOneLineNamingFileAndKeyAndNoSession) {
  const std::filesystem::path profile =
      testing::write_file(dir_, "bad.toml", "name = \"x\"\n[inputs.humidity]\nain = 7\n");
  const testing::ProcessResult r =
      run_cli({"run", "--device", "t7", "--t7", address_, "--clock", "wall", "--rig-profile", profile.string()});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err, "bellows: rig profile " + profile.string() +
                       ": [inputs.humidity]: unknown input (chamber_a, chamber_b, supply, angle, temperature)\n");
  EXPECT_TRUE(no_session_saved());
}

TEST_F(T7Processes, AnUnreachableAddressIsOneLineExitFourAndNoSession) {
  const testing::ProcessResult r = run_cli({"run", "--device", "t7", "--t7", address_, "--clock", "wall"});
  EXPECT_EQ(r.exit_code, 4) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("bellows: t7 " + address_ + ": cannot connect"), std::string::npos) << r.err;
  EXPECT_TRUE(no_session_saved());
}

TEST_F(T7Processes, AMalformedAddressIsBadInput) {
  const testing::ProcessResult r = run_cli({"run", "--device", "t7", "--t7", "127.0.0.1:http", "--clock", "wall"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err, "bellows: --t7 '127.0.0.1:http': the port must be a number 1..65535\n");
  const testing::ProcessResult missing = run_cli({"run", "--device", "t7", "--clock", "wall"});
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_EQ(missing.err, "bellows: --device t7 needs --t7 HOST[:PORT]\n");
}

}  // namespace
}  // namespace bellows
