// The T7 device against t7-sim's server in the same process, on 127.0.0.1 (a free port): the
// configuration it writes, duty cycles and calibrated readings both ways, health and raw inputs,
// the exception for an unknown register, the watchdog, and a link that dies.
#include <gtest/gtest.h>

#include <errno.h>
#include <signal.h>
#include <sys/syscall.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <thread>

#include "app/rig_profile_file.hpp"
#include "devices/modbus_client.hpp"
#include "devices/t7_device.hpp"
#include "devices/t7_sim_server.hpp"
#include "devices/t7_errors.hpp"
#include "engine/base/cancellation.hpp"
#include "engine/base/errors.hpp"
#include "engine/control/safety.hpp"

namespace bellows {
namespace {

/// t7-sim's server on its own thread, on a free loopback port.
class SimThread {
 public:
  explicit SimThread(T7SimOptions options = {}) {
    if (options.profile.name.empty()) options.profile = paper_rig_profile();
    options.port = 0;
    server_ = std::make_unique<T7SimServer>(std::move(options));
    thread_ = std::thread([this] { server_->run([this] { return stop_.load(); }, [](const std::string&) {}); });
  }
  ~SimThread() { stop(); }
  void stop() {
    stop_.store(true);
    if (thread_.joinable()) thread_.join();
  }
  int port() const { return server_->port(); }
  T7SimStatus status() const { return server_->status(); }

 private:
  std::unique_ptr<T7SimServer> server_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

T7DeviceOptions device_options(int port) {
  T7DeviceOptions o;
  o.port = port;
  o.profile = paper_rig_profile();
  o.realtime = false;
  o.link.response_timeout_s = 0.05;  // a loaded test machine: the timeout is not what is tested here
  return o;
}

/// Polls `done` for up to 10 s (a generous bound for a loaded machine; no timing is asserted).
bool eventually(const std::function<bool()>& done) {
  for (int i = 0; i < 1000; ++i) {
    if (done()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return done();
}

TEST(T7Loopback, ConnectingConfiguresTheWatchdogAndLeavesTheValvesVented) {
  SimThread sim;
  T7Device device(device_options(sim.port()));
  ASSERT_TRUE(eventually([&] {
    const T7SimStatus s = sim.status();
    return s.requests > 30 && s.watchdog_enabled && s.last_request_s > 0.0 && device.health().exchanges > 3 &&
           s.requests > 60;
  }));
  const T7SimStatus s = sim.status();
  EXPECT_EQ(s.watchdog_timeout_s, 1u);
  EXPECT_TRUE(s.safe);
  EXPECT_EQ(s.duty[static_cast<int>(ValveRole::kOutletA)], 1.0);
  EXPECT_EQ(s.duty[static_cast<int>(ValveRole::kInletA)], 0.0);
  EXPECT_EQ(s.exceptions, 0u);  // every register bellows touches exists on a T7
}

TEST(T7Loopback, DutyCyclesReachTheLinesAndCalibratedReadingsComeBack) {
  SimThread sim;
  T7Device device(device_options(sim.port()));
  ValveCommand command;
  command.joint[0].inlet_duty = {0.25, 0.0};
  command.joint[0].outlet_duty = {0.0, 0.5};
  // The engine sends a command every tick; so does this loop, until the lines show it.
  ASSERT_TRUE(eventually([&] {
    device.write_valves(command);
    const T7SimStatus s = sim.status();
    return s.duty[0] == 0.25 && s.duty[1] == 0.0 && s.duty[2] == 0.0 && s.duty[3] == 0.5;
  }));
  EXPECT_FALSE(sim.status().safe);
  device.vent();
  ASSERT_TRUE(eventually([&] { return sim.status().safe; }));

  SensorReading r;
  ASSERT_TRUE(eventually([&] {
    r = device.read_sensors();
    return r.time_s > 0.0;
  }));
  const PlantParameters plant;
  EXPECT_NEAR(r.supply_bar, plant.supply_bar, 0.05);  // through volts and back
  EXPECT_NEAR(r.temperature_K, plant.gas.temperature_K, 0.5);
  EXPECT_LT(std::abs(r.joint[0].angle_rad), 0.2);
  EXPECT_GT(r.joint[0].chamber_bar[0], 0.9);

  const RawInputs raw = device.raw_inputs();
  ASSERT_EQ(raw.count, 5);
  EXPECT_STREQ(raw.inputs[2].name, "supply");
  EXPECT_STREQ(raw.inputs[2].unit, "bar");
  EXPECT_NEAR(raw.inputs[2].volts, plant.supply_bar - plant.gas.ambient_bar, 0.05);  // 1 bar per volt above ambient
  EXPECT_STREQ(raw.inputs[3].unit, "deg");

  const DeviceHealth h = device.health();
  EXPECT_TRUE(h.has_link);
  EXPECT_TRUE(h.connected);
  EXPECT_GT(h.exchanges, 0u);
  EXPECT_EQ(h.link_errors, 0u);
  EXPECT_GT(h.round_trip_max_ms, 0.0);
  EXPECT_LE(h.round_trip_p50_ms, h.round_trip_max_ms);
}

TEST(T7Loopback, WhenTheEngineFallsSilentTheLinkVentsByItselfAndKeepsTheWatchdogFed) {
  SimThread sim;
  T7Device device(device_options(sim.port()));
  ValveCommand open_inlet;
  open_inlet.joint[0].inlet_duty = {1.0, 0.0};
  open_inlet.joint[0].outlet_duty = {0.0, 1.0};
  ASSERT_TRUE(eventually([&] {
    device.write_valves(open_inlet);
    return sim.status().duty[static_cast<int>(ValveRole::kInletA)] == 1.0;
  }));
  // No more commands (a hung engine loop): within [t7] command_timeout_s the I/O thread vents.
  ASSERT_TRUE(eventually([&] { return sim.status().safe; }));
  // It keeps exchanging, so the T7's watchdog never has to act while bellows lives.
  const std::uint64_t exchanges = device.health().exchanges;
  ASSERT_TRUE(eventually([&] { return device.health().exchanges > exchanges + 10; }));
  EXPECT_EQ(sim.status().watchdog_actions, 0);
}

// The rig enforces its own limits whatever it is sent (issue 16): a client that keeps writing both
// inlets open meets the pressure ceiling, every time, while the lines keep showing what it wrote.
// Without the limit (a ceiling out of reach) the same client drives the chambers far above it.
/// A client writing `command` for 3 s, one write every 5 ms like the engine's ticks, to a t7-sim
/// with `limits`: the largest `measure` of its status seen meanwhile; `last` is its final status.
double largest_while_writing(const RigLimits& limits, const ValveCommand& command,
                             const std::function<double(const T7SimStatus&)>& measure, T7SimStatus& last) {
  T7SimOptions options;
  options.limits = limits;
  SimThread sim(options);
  T7Device device(device_options(sim.port()));
  double largest = 0.0;
  for (int i = 0; i < 600; ++i) {
    device.write_valves(command);
    last = sim.status();
    largest = std::max(largest, measure(last));
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return largest;
}

double highest_chamber_bar_while_inlets_open(const RigLimits& limits, T7SimStatus& last) {
  ValveCommand both_inlets_open;  // both chambers fill: the arm stays near its middle
  both_inlets_open.joint[0].inlet_duty = {1.0, 1.0};
  both_inlets_open.joint[0].outlet_duty = {0.0, 0.0};
  return largest_while_writing(
      limits, both_inlets_open, [](const T7SimStatus& s) { return std::max(s.chamber_bar[0], s.chamber_bar[1]); },
      last);
}

TEST(T7Loopback, TheRigKeepsItsPressureCeilingWhateverTheClientWrites) {
  RigLimits limits;
  limits.pressure_ceiling_bar = 1.75;
  T7SimStatus last;
  const double highest = highest_chamber_bar_while_inlets_open(limits, last);
  EXPECT_GE(last.pressure_limit_trips, 1) << "the chambers never reached the ceiling";
  EXPECT_LT(highest, limits.pressure_ceiling_bar + 0.1) << "a chamber went beyond the ceiling";
  EXPECT_EQ(last.duty[static_cast<int>(ValveRole::kInletA)], 1.0) << "the line still shows what the client wrote";

  RigLimits none;
  none.pressure_ceiling_bar = 100.0;
  const double unlimited = highest_chamber_bar_while_inlets_open(none, last);
  EXPECT_GT(unlimited, limits.pressure_ceiling_bar + 0.5) << "the client alone would go far beyond the ceiling";
  EXPECT_EQ(last.pressure_limit_trips, 0);
}

// The same for the angle: a client that keeps turning the arm (A fills, B vents) is vented each time
// the arm leaves the rig's range; without that range the arm goes much further.
double widest_angle_rad_while_turning(const RigLimits& limits, T7SimStatus& last) {
  ValveCommand turn;
  turn.joint[0].inlet_duty = {1.0, 0.0};
  turn.joint[0].outlet_duty = {0.0, 1.0};
  return largest_while_writing(
      limits, turn, [](const T7SimStatus& s) { return std::abs(s.angle_rad); }, last);
}

TEST(T7Loopback, AnArmBeyondTheRigsAngleRangeIsVentedWhateverTheClientWrites) {
  RigLimits narrow;
  narrow.angle_limit_rad = 0.2;
  T7SimStatus last;
  const double limited = widest_angle_rad_while_turning(narrow, last);
  EXPECT_GE(last.angle_limit_trips, 1) << "the arm never left the range";
  RigLimits wide;
  wide.angle_limit_rad = 3.0;
  const double unlimited = widest_angle_rad_while_turning(wide, last);
  EXPECT_EQ(last.angle_limit_trips, 0);
  EXPECT_LT(limited, unlimited - 0.1) << "limited " << limited << " rad, unlimited " << unlimited << " rad";
}

TEST(T7Loopback, SwappedChamberWiringShowsOnTheInputs) {
  T7SimOptions options;
  options.swapped_chambers = true;
  SimThread sim(options);
  T7Device device(device_options(sim.port()));
  ValveCommand inflate_a;
  inflate_a.joint[0].inlet_duty = {1.0, 0.0};
  inflate_a.joint[0].outlet_duty = {0.0, 1.0};
  SensorReading r;
  ASSERT_TRUE(eventually([&] {
    device.write_valves(inflate_a);
    r = device.read_sensors();
    return r.joint[0].chamber_bar[1] > 1.5;  // chamber A fills, but its pressure shows on B's input
  }));
  EXPECT_LT(r.joint[0].chamber_bar[0], r.joint[0].chamber_bar[1] - 0.1);
  device.vent();
}

TEST(T7Loopback, AVoltageOutsideItsValidRangeIsASensorRangeFault) {
  SimThread sim;
  T7DeviceOptions options = device_options(sim.port());
  options.profile.input(SensorRole::kSupply).volts_max_V = 1.0;  // the simulated supply reads ~2 V
  T7Device device(options);
  SensorReading r;
  ASSERT_TRUE(eventually([&] {
    r = device.read_sensors();
    return r.time_s > 0.0;
  }));
  EXPECT_EQ(r.supply_bar, kOutOfRangePressure_bar);
  GuardInputs inputs;
  inputs.p_max_bar = ControllerParameters{}.p_max_bar;
  EXPECT_EQ(check_guards(r, inputs, SafetyParameters{}), FaultCode::kSensorOutOfRange);
}

/// Chamber B while its inlet line is held fully open (outlet shut), one write every 5 ms like the
/// engine's ticks: its reading after 200 ms, or, given `enough`, the first reading after that for
/// which it holds, writing on meanwhile (a loaded machine may fill the chamber later: `eventually`).
double chamber_b_while_inflating(T7SimOptions options, double& supply_bar,
                                 const std::function<bool(double)>& enough = {}) {
  SimThread sim(std::move(options));
  T7Device device(device_options(sim.port()));
  ValveCommand inflate_b;
  inflate_b.joint[0].inlet_duty = {0.0, 1.0};
  inflate_b.joint[0].outlet_duty = {1.0, 0.0};
  EXPECT_TRUE(eventually([&] {
    device.write_valves(inflate_b);
    return sim.status().duty[static_cast<int>(ValveRole::kInletB)] == 1.0;
  }));
  for (int i = 0; i < 40; ++i) {  // 200 ms of ticks
    device.write_valves(inflate_b);
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  SensorReading r = device.read_sensors();
  if (enough) {
    eventually([&] {
      device.write_valves(inflate_b);
      r = device.read_sensors();
      return enough(r.joint[0].chamber_bar[1]);
    });
  }
  supply_bar = r.supply_bar;
  device.vent();
  return r.joint[0].chamber_bar[1];
}

TEST(T7Loopback, DrillsADeadInletAndNoSupply) {
  const PlantParameters plant;
  const double inflated_bar = plant.gas.ambient_bar + 0.3;
  double supply_bar = 0.0;
  EXPECT_GT(chamber_b_while_inflating({}, supply_bar, [&](double bar) { return bar > inflated_bar; }),
            inflated_bar);  // a healthy rig inflates
  EXPECT_NEAR(supply_bar, plant.supply_bar, 0.05);
  T7SimOptions dead;
  dead.dead_valve = ValveRole::kInletB;
  EXPECT_LT(chamber_b_while_inflating(dead, supply_bar), plant.gas.ambient_bar + 0.1);  // its line opens, the valve not
  T7SimOptions no_supply;
  no_supply.no_supply = true;
  EXPECT_LT(chamber_b_while_inflating(no_supply, supply_bar), plant.gas.ambient_bar + 0.1);
  EXPECT_NEAR(supply_bar, plant.gas.ambient_bar, 0.05);
}

TEST(T7Loopback, AnUnknownRegisterGetsTheExceptionAT7Gives) {
  SimThread sim;
  ModbusClient client("127.0.0.1", sim.port());
  ASSERT_EQ(client.connect(2.0), "");
  client.set_response_timeout(1.0);
  std::uint16_t registers[2];
  EXPECT_FALSE(client.read(12345, 2, registers));
  EXPECT_NE(client.last_error().find("Modbus exception 2"), std::string::npos) << client.last_error();
  EXPECT_FALSE(client.write_float(t7::kAin(0), 1.0));  // AIN# is read only
  EXPECT_NE(client.last_error().find("Modbus exception 2"), std::string::npos) << client.last_error();
  double product = 0.0;
  EXPECT_TRUE(client.read_float(t7::kProductId, product));
  EXPECT_EQ(product, 7.0);
  EXPECT_TRUE(eventually([&] { return sim.status().exceptions == 2u; })) << sim.status().exceptions;
}

TEST(T7Loopback, TheWatchdogVentsWhatASilentClientLeftOpen) {
  SimThread sim;
  {
    T7Device device(device_options(sim.port()));  // configures the watchdog and the PWM lines
  }
  // A client that opens an inlet and falls silent, as a killed bellows would.
  ModbusClient client("127.0.0.1", sim.port());
  ASSERT_EQ(client.connect(2.0), "");
  client.set_response_timeout(1.0);
  const int actions_before = sim.status().watchdog_actions;
  ASSERT_TRUE(client.write_u32(t7::kDioEfConfigA(2), 399999));  // inlet_a fully open (roll - 1: the most a T7 takes)
  ASSERT_TRUE(client.write_u32(t7::kDioEfConfigA(4), 0));       // outlet_a shut
  ASSERT_TRUE(eventually([&] { return !sim.status().safe; }));  // the status is published every 10 ms
  ASSERT_TRUE(eventually([&] { return sim.status().watchdog_actions > actions_before; }));
  const T7SimStatus s = sim.status();
  EXPECT_TRUE(s.safe);
  EXPECT_EQ(s.duty[static_cast<int>(ValveRole::kInletA)], 0.0);
  EXPECT_EQ(s.duty[static_cast<int>(ValveRole::kOutletA)], 1.0);
  // It acted after one timeout of silence, and the lines were safe within a PWM period of its action
  // (of the action, not of the silence's start: when t7-sim's thread notices the timeout is its host's
  // scheduling, which a loaded machine delays by tens of ms).
  EXPECT_GE(s.last_watchdog_action_s - s.last_request_s, 1.0);
  EXPECT_GE(s.safe_since_s, s.last_watchdog_action_s);
  EXPECT_LE(s.safe_since_s - s.last_watchdog_action_s, 1.0 / 200.0);
}

// A lab once saved the power-up defaults with PWM running (Kipling's "save as power-up defaults", or
// IO_CONFIG_SET_BOOTUP_TO_CURRENT): the watchdog must still vent. Its reset to the power-up defaults
// (WATCHDOG_ADVANCED_DEFAULT = 2) would bring that PWM back, inlets open; the factory's (1) ends it.
TEST(T7Loopback, TheWatchdogVentsEvenIfTheLabSavedPwmAsThePowerUpDefaults) {
  SimThread sim;
  { T7Device device(device_options(sim.port())); }
  ModbusClient client("127.0.0.1", sim.port());
  ASSERT_EQ(client.connect(2.0), "");
  client.set_response_timeout(1.0);
  std::uint32_t advanced = 0, factory = 0;
  ASSERT_TRUE(client.read_u32(t7::kWatchdogAdvanced, advanced));
  EXPECT_EQ(advanced, t7::kWatchdogAdvancedIoConfigToFactory);
  ASSERT_TRUE(client.write_u32(t7::kDioEfConfigA(2), 399999));        // inlet_a fully open...
  ASSERT_TRUE(client.write_u32(t7::kIoConfigSetBootupToCurrent, 1));  // ...saved as the power-up defaults
  ASSERT_TRUE(client.read_u32(t7::kIoConfigCheckForFactory, factory));
  EXPECT_EQ(factory, 0u);
  const int actions_before = sim.status().watchdog_actions;
  ASSERT_TRUE(eventually([&] { return !sim.status().safe; }));
  ASSERT_TRUE(eventually([&] { return sim.status().watchdog_actions > actions_before; }));
  const T7SimStatus s = sim.status();
  EXPECT_TRUE(s.safe);
  EXPECT_EQ(s.duty[static_cast<int>(ValveRole::kInletA)], 0.0);
  EXPECT_EQ(s.duty[static_cast<int>(ValveRole::kOutletA)], 1.0);
}

TEST(T7Loopback, ADeadLinkStopsTheReadingsAndSaysWhichLink) {
  auto sim = std::make_unique<SimThread>();
  T7Device device(device_options(sim->port()));
  ASSERT_TRUE(eventually([&] { return device.health().exchanges > 5; }));
  sim.reset();  // the server goes away mid-run
  ASSERT_TRUE(eventually([&] { return !device.health().connected; }));
  EXPECT_GT(device.health().link_errors, 0u);
  EXPECT_FALSE(device.link_error().empty());
  // No fresh reading from now on: the engine's stale guard sees the time stand still.
  device.read_sensors();
  const double frozen = device.read_sensors().time_s;
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  EXPECT_EQ(device.read_sensors().time_s, frozen);
  EXPECT_GT(device.health().stale_readings, 0u);
}

/// The thread of this process named `name` (its comm), 0 when there is none.
pid_t thread_named(const std::string& name) {
  for (const auto& task : std::filesystem::directory_iterator("/proc/self/task")) {
    std::ifstream comm(task.path() / "comm");
    std::string line;
    if (std::getline(comm, line) && line == name) return static_cast<pid_t>(std::stoi(task.path().filename()));
  }
  return 0;
}

// How long a thread sent SIGUSR2 sleeps in its handler: as long as a host that holds it off its core.
constexpr long kHeldOff_ms = 400;
extern "C" void held_off(int) {
  const int saved_errno = errno;  // the thread was interrupted mid-call: leave it its errno
  const timespec held{0, kHeldOff_ms * 1000000L};
  nanosleep(&held, nullptr);
  errno = saved_errno;
}

// The T7 answers, but this host does not run the link's I/O thread (a loaded machine holding it off
// its core): no reading arrives, and the silence is named for the host, not the T7 or its cable.
TEST(T7Loopback, ASilenceOfThisHostsIoThreadIsNamedForTheHostNotTheT7) {
  SimThread sim;
  T7Device device(device_options(sim.port()));
  ASSERT_TRUE(eventually([&] { return device.health().exchanges > 5; }));
  const pid_t io_thread = thread_named("bellows-t7-io");
  ASSERT_NE(io_thread, 0) << "the link's I/O thread is named bellows-t7-io";
  // A healthy link's silence is not the host's (judged on a 1 s silence: on a loaded test machine the
  // host may well hold the thread for the 20 ms that half the default stale limit is).
  DeviceFault running;
  device.explain_silence(1.0, running);
  EXPECT_EQ(std::string(running.text.data()).find("I/O thread did not run"), std::string::npos) << running.text.data();

  struct sigaction action {};
  action.sa_handler = held_off;
  struct sigaction before {};
  ASSERT_EQ(sigaction(SIGUSR2, &action, &before), 0);
  ASSERT_EQ(syscall(SYS_tgkill, getpid(), io_thread, SIGUSR2), 0);
  std::this_thread::sleep_for(std::chrono::milliseconds(kHeldOff_ms / 2));
  DeviceFault held;
  device.explain_silence(0.04, held);  // [safety] stale_ticks 8 at 200 Hz
  const std::string text = held.text.data();
  EXPECT_EQ(held.code, FaultCode::kLinkLost) << text;
  EXPECT_NE(text.find("no reading of the T7 at 127.0.0.1:"), std::string::npos) << text;
  EXPECT_NE(text.find("this host's T7 I/O thread did not run for"), std::string::npos) << text;

  // Back on its core, it exchanges again and the silence is no longer the host's.
  const std::uint64_t exchanges = device.health().exchanges;
  ASSERT_TRUE(eventually([&] { return device.health().exchanges > exchanges + 5; }));
  sigaction(SIGUSR2, &before, nullptr);
  DeviceFault again;
  device.explain_silence(1.0, again);
  EXPECT_EQ(std::string(again.text.data()).find("I/O thread did not run"), std::string::npos) << again.text.data();
}

// One answer comes late (a busy network or T7): its request times out, and the answers queued
// behind it arrive in a burst. The link drops them and answers again by itself, each request with
// its own answer. (Dropping at once, before they landed, left it one answer behind for good: every
// answer refused for its transaction id, no fresh reading ever again; CI met it as a hung zeroing.)
TEST(T7Loopback, ALateAnswerIsDroppedAndTheLinkAnswersAgain) {
  T7SimOptions options;
  options.stall_after_s = 0.2;
  options.stall_s = 0.3;  // six of the device's response timeouts
  SimThread sim(options);
  T7Device device(device_options(sim.port()));
  ASSERT_TRUE(eventually([&] { return device.health().link_errors > 0; })) << "the late answer timed out";
  // Answered in time again: the queue behind the stall is worked off (a late reading handed over
  // while it drains says `connected` too, before its last timeouts).
  const std::uint64_t exchanges_at_stall = device.health().exchanges;
  ASSERT_TRUE(eventually([&] {
    return device.health().connected && device.health().exchanges > exchanges_at_stall + 1;
  })) << device.link_error();
  EXPECT_EQ(sim.status().stalls, 1);
  // The drain is over once ten exchanges in a row have answered in time (a late read handed over
  // while the requests queued behind the stall are worked off says `connected` too; CI met one more
  // timeout after the first two exchanges answered again, at a load of two).
  DeviceHealth since_last_error = device.health();
  ASSERT_TRUE(eventually([&] {
    const DeviceHealth now = device.health();
    if (now.link_errors != since_last_error.link_errors) since_last_error = now;
    return now.exchanges >= since_last_error.exchanges + 10;
  })) << device.link_error();
  const DeviceHealth after_stall = device.health();
  const double time_s = device.read_sensors().time_s;
  ASSERT_TRUE(eventually([&] { return device.health().exchanges > after_stall.exchanges + 50; }));
  EXPECT_EQ(device.health().link_errors, after_stall.link_errors) << "every request reads its own answer again";
  EXPECT_GT(device.read_sensors().time_s, time_s) << "fresh readings";
  EXPECT_GT(device.late_answers(), 0u) << "the late answers were read and dropped by transaction id";
  EXPECT_EQ(device.reconnects(), 0u) << "on the same connection";
  EXPECT_LE(sim.status().max_clients, 1);
}

TEST(T7Loopback, AnAddressWhereNothingListensIsAnEnvironmentError) {
  int port = 0;
  {
    SimThread sim;  // a port that was free a moment ago, and is closed again
    port = sim.port();
  }
  T7DeviceOptions options = device_options(port);
  options.link.connect_timeout_s = 1.0;
  try {
    T7Device device(options);
    FAIL() << "connected to nothing";
  } catch (const EnvironmentError& error) {
    EXPECT_NE(std::string(error.what()).find("t7 127.0.0.1:" + std::to_string(port) + ": cannot connect"),
              std::string::npos)
        << error.what();
  }
}

// ---- t7-sim as strict as a T7 (devices/t7_sim_rules.hpp), and bellows breaking none of its rules ----

/// A raw client of the simulated T7: each call expects the T7's answer, refusals included.
struct RawT7 {
  explicit RawT7(int port) : client("127.0.0.1", port) {
    EXPECT_EQ(client.connect(2.0), "");
    client.set_response_timeout(2.0);
  }
  /// The LabJack error a refused request left in LAST_ERR_DETAIL, with the Modbus exception (0: served).
  std::pair<int, int> refusal_of(bool served) {
    if (served) return {0, 0};
    const int exception = client.last_exception();
    std::uint16_t detail = 0;
    EXPECT_TRUE(client.read_u16(t7::kLastErrDetail, detail)) << client.last_error();
    return {exception, detail};
  }
  std::pair<int, int> u16(int address, std::uint16_t value) { return refusal_of(client.write_u16(address, value)); }
  std::pair<int, int> u32(int address, std::uint32_t value) { return refusal_of(client.write_u32(address, value)); }
  ModbusClient client;
};

TEST(T7SimStrict, RefusesWhatLabJackDocumentsAT7Refuses) {
  SimThread sim;
  RawT7 t7(sim.port());
  using P = std::pair<int, int>;
  const int failure = t7::kExceptionDeviceFailure;
  EXPECT_EQ(t7.u16(t7::kClockEnable(1), 0), P(failure, 2554)) << "disabling a clock that is not running";
  EXPECT_EQ(t7.u16(t7::kClock0Divisor, 3), P(failure, 2559)) << "a divisor a T7 has not";
  EXPECT_EQ(t7.u16(t7::kClockEnable(1), 1), P(0, 0));
  EXPECT_EQ(t7.u16(t7::kClock0Enable, 1), P(failure, 2558)) << "clock 0 while clock 1 runs";
  EXPECT_EQ(t7.u16(t7::kClockEnable(1), 0), P(0, 0));
  EXPECT_EQ(t7.u32(t7::kClock0RollValue, 400000), P(0, 0));
  EXPECT_EQ(t7.u16(t7::kClock0Enable, 1), P(0, 0));
  EXPECT_EQ(t7.u32(t7::kDioEfConfigA(2), 400000), P(failure, 2565)) << "CONFIG_A = roll (100 % the naive way)";
  EXPECT_EQ(t7.u32(t7::kDioEfConfigA(2), 399999), P(0, 0)) << "roll - 1, the most it takes";
  EXPECT_EQ(t7.u32(t7::kDioEfEnable(2), 1), P(failure, 2563)) << "PWM on a line that is an input";
  EXPECT_EQ(t7.u16(t7::kFio(2), 1), P(0, 0));
  EXPECT_EQ(t7.u32(t7::kDioEfEnable(2), 1), P(failure, 2563)) << "PWM on a line driven high";
  EXPECT_EQ(t7.u16(t7::kFio(2), 0), P(0, 0));
  EXPECT_EQ(t7.u32(t7::kDioEfEnable(2), 1), P(0, 0)) << "an output driven low";
  EXPECT_EQ(t7.u32(t7::kDioEfIndex(2), 1), P(failure, 2566)) << "a new index while enabled";
  EXPECT_EQ(t7.u16(t7::kAinResolutionIndex(0), 13), P(t7::kExceptionIllegalDataValue, 2375))
      << "AIN_RESOLUTION_INVALID, the device's own error (not LJM's 1203)";
  EXPECT_EQ(t7.refusal_of(t7.client.write_float(t7::kAinSettling_us(0), 60000.0)),
            P(t7::kExceptionIllegalDataValue, 2371))
      << "AIN_SETTLING_INVALID: more than the device's maximum";
  EXPECT_EQ(t7.u16(t7::kAinResolutionIndex(0), 12), P(0, 0)) << "a T7-Pro samples at 12";
  EXPECT_EQ(t7.refusal_of(t7.client.write_float(t7::kAin(0), 1.0)), P(t7::kExceptionIllegalDataAddress, 1202))
      << "read only";
  std::uint16_t r[2];
  EXPECT_EQ(t7.refusal_of(t7.client.read(12345, 2, r)), P(t7::kExceptionIllegalDataAddress, 1202)) << "no such address";
  ASSERT_TRUE(eventually([&] { return sim.status().exceptions == 11u; })) << sim.status().exceptions;
  EXPECT_EQ(sim.status().refusals, 9u);  // the rules' (not the addresses')
  EXPECT_EQ(sim.status().last_refused_error, 2371);
}

// Another program streams from the T7 (its other connection): its analog inputs are not read
// command-response meanwhile. bellows says so at connect, in one line, before it writes anything.
TEST(T7SimStrict, AStreamOfAnotherProgramIsRefusedAtConnectBeforeAnyWrite) {
  T7SimOptions options;
  options.streaming = true;
  SimThread sim(options);
  RawT7 t7(sim.port());
  std::uint16_t r[2];
  EXPECT_EQ(t7.refusal_of(t7.client.read(t7::kAin(0), 2, r)),
            std::make_pair(t7::kExceptionDeviceFailure, t7::kErrorStreamIsActive));
  try {
    T7Device device(device_options(sim.port()));
    ADD_FAILURE() << "connected to a T7 that streams";
  } catch (const EnvironmentError& error) {
    EXPECT_NE(std::string(error.what()).find("another program streams from this T7 (STREAM_ENABLE = 1"),
              std::string::npos)
        << error.what();
  }
  std::uint32_t watchdog = 1;
  ASSERT_TRUE(t7.client.read_u32(t7::kWatchdogEnable, watchdog)) << t7.client.last_error();
  EXPECT_EQ(watchdog, 0u) << "the watchdog was written before the refusal";
}

// Valves on DIO0 and DIO2..4: every tick's one write of CONFIG_A spans DIO1 too. While another
// program runs an extended feature there (an interrupt counter, index 8), bellows refuses to connect
// instead of writing its CONFIG_A 200 times a second; with DIO1's feature off it connects.
TEST(T7SimStrict, AnExtendedFeatureBetweenTheValveLinesIsRefusedAtConnect) {
  RigProfile profile = paper_rig_profile();
  profile.valve_dio = {0, 2, 3, 4};
  T7SimOptions options;
  options.profile = profile;
  SimThread sim(options);
  RawT7 t7(sim.port());
  ASSERT_EQ(t7.u32(t7::kDioEfIndex(1), 8), std::make_pair(0, 0));
  ASSERT_EQ(t7.u32(t7::kDioEfEnable(1), 1), std::make_pair(0, 0));
  T7DeviceOptions device = device_options(sim.port());
  device.profile = profile;
  try {
    T7Device refused(device);
    ADD_FAILURE() << "connected over another program's extended feature on DIO1";
  } catch (const EnvironmentError& error) {
    EXPECT_NE(std::string(error.what()).find("DIO1 runs an extended feature (DIO1_EF_ENABLE = 1)"), std::string::npos)
        << error.what();
  }
  ASSERT_EQ(t7.u32(t7::kDioEfEnable(1), 0), std::make_pair(0, 0));
  T7Device connected(device);
  EXPECT_TRUE(eventually([&] { return connected.health().exchanges > 3; }));
}

TEST(T7SimStrict, APlainT7RefusesTheProsResolutionIndices) {
  T7SimOptions options;
  options.product = t7::Product::kT7;
  SimThread sim(options);
  RawT7 t7(sim.port());
  EXPECT_EQ(t7.u16(t7::kAinResolutionIndex(3), 9), std::make_pair(t7::kExceptionIllegalDataValue, 2375));
  EXPECT_EQ(t7.u16(t7::kAinResolutionIndex(3), 8), std::make_pair(0, 0));
  std::uint32_t hardware = 1;
  ASSERT_TRUE(t7.client.read_u32(t7::kHardwareInstalled, hardware));
  EXPECT_EQ(hardware & t7::kHardwareHighResolutionAdc, 0u);
}

// The other side of each refusal: a whole session of bellows (connect, configure, exchanges, the
// last vent) sends none of them, on a strict T7-Pro and on a T7, over one connection.
TEST(T7SimStrict, BellowsSendsNothingAT7WouldRefuseAndHoldsOneConnection) {
  for (t7::Product product : {t7::Product::kT7Pro, t7::Product::kT7}) {
    T7SimOptions options;
    options.product = product;
    SimThread sim(options);
    {
      T7Device device(device_options(sim.port()));
      EXPECT_EQ(device.product(), product);
      ValveCommand open = ValveCommand::vented();
      open.joint[0].inlet_duty = {1.0, 0.3};  // fully open inlets are roll - 1 too
      open.joint[0].outlet_duty = {0.0, 1.0};
      device.write_valves(open);
      ASSERT_TRUE(eventually([&] { return device.health().exchanges > 40; }));
      device.vent();
    }
    ASSERT_TRUE(eventually([&] { return sim.status().clients == 0; }));
    {
      T7Device again(
          device_options(sim.port()));  // what the first left running (clock 0, PWM) is reconfigured as documented
      ASSERT_TRUE(eventually([&] { return again.health().exchanges > 5; }));
    }
    ASSERT_TRUE(eventually([&] { return sim.status().clients == 0; }));
    const T7SimStatus s = sim.status();
    EXPECT_EQ(s.exceptions, 0u) << "LabJack error " << s.last_refused_error << " ("
                                << t7::error_name(s.last_refused_error) << ")";
    EXPECT_EQ(s.refusals, 0u);
    EXPECT_EQ(s.max_clients, 1) << "never two connections at once";
    EXPECT_TRUE(s.safe);
  }
}

TEST(T7SimStrict, AThirdConnectionIsClosedAtOnce) {
  SimThread sim;
  RawT7 first(sim.port()), second(sim.port());
  double product = 0.0;
  EXPECT_TRUE(first.client.read_float(t7::kProductId, product));
  EXPECT_TRUE(second.client.read_float(t7::kProductId, product));
  ModbusClient third("127.0.0.1", sim.port());
  ASSERT_EQ(third.connect(2.0), "");  // TCP accepts it; the T7 closes it
  third.set_response_timeout(2.0);
  EXPECT_FALSE(third.read_float(t7::kProductId, product));
  ASSERT_TRUE(eventually([&] { return sim.status().refused_connections == 1; }));
  EXPECT_EQ(sim.status().max_clients, 2);
}

// A read costs the link's overhead and each input's sample time at its index (LabJack's A-1 and
// A-3-2-2): index 0 on a T7-Pro is its default 9, 3.5 ms per input. Lower bounds only (the sim
// sleeps at least so long; a loaded machine only adds).
TEST(T7SimStrict, ReadsTakeAsLongAsLabJackSays) {
  SimThread sim;
  RawT7 t7(sim.port());
  std::uint16_t r[10];
  const auto timed_read = [&] {
    const double start = monotonic_seconds();
    EXPECT_TRUE(t7.client.read(t7::kAin(0), 10, r)) << t7.client.last_error();
    return monotonic_seconds() - start;
  };
  EXPECT_GE(timed_read(), 0.001 + 5 * 0.0035) << "five inputs at the Pro's default index 9";
  for (int ain = 0; ain < 5; ++ain) ASSERT_EQ(t7.u16(t7::kAinResolutionIndex(ain), 12), std::make_pair(0, 0));
  EXPECT_GE(timed_read(), 0.001 + 5 * 0.159) << "at index 12";
}

TEST(T7Timing, TheTableAndTheProductDefaults) {
  using t7::Product;
  EXPECT_DOUBLE_EQ(t7::sample_time_s(0, 0.0, Product::kT7), 0.0011);     // index 8
  EXPECT_DOUBLE_EQ(t7::sample_time_s(0, 0.0, Product::kT7Pro), 0.0035);  // index 9
  EXPECT_DOUBLE_EQ(t7::sample_time_s(4, 100.0, Product::kT7Pro), 0.0002);
  const RigProfile paper = paper_rig_profile();
  const t7::ExchangeTime t = t7::exchange_time(paper, Product::kT7Pro);
  EXPECT_EQ(t.inputs, 5);
  EXPECT_NEAR(t.exchange_s, 0.0025, 1e-9) << "1 ms write + 1 ms + 5 x 0.1 ms read: half the 5 ms tick";
  EXPECT_NO_THROW(t7::require_exchange_fits(paper, Product::kT7Pro, 0.005, 0.004));
}

// resolution_index = 12 on five inputs: 5 x 159 ms. Refused before any traffic (nothing listens
// at the port: the refusal is not a connection error), naming the key and the read time.
TEST(T7Timing, AProfileWhoseReadCannotFitTheTickIsRefusedBeforeConnecting) {
  T7DeviceOptions options = device_options(1);  // port 1: nothing listens
  for (SensorRole role : kSensorRoles) options.profile.input(role).resolution_index = 12;
  try {
    T7Device device(options);
    FAIL() << "connected";
  } catch (const InputError& error) {
    const std::string what = error.what();
    EXPECT_NE(what.find("[inputs.chamber_a] resolution_index = 12"), std::string::npos) << what;
    EXPECT_NE(what.find("one read of 5 inputs takes 796.0 ms"), std::string::npos) << what;
    EXPECT_NE(what.find("5.0 ms tick"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << "one line";
  }
  for (SensorRole role : kSensorRoles) options.profile.input(role).resolution_index = 0;  // the Pro's default, 9
  EXPECT_THROW(T7Device{options}, InputError);
}

// ---- a late answer costs no tick when it comes before the next command (issue 22) ----

TEST(T7Loopback, AReadAnsweredAfterItsDeadlineIsStillHandedOver) {
  T7SimOptions options;
  options.answer_after_s = 0.02;  // every answer 20 ms late: the write fits a 30 ms deadline, write and read do not
  SimThread sim(options);
  T7DeviceOptions o = device_options(sim.port());
  o.tick_s = 0.2;  // without commands, exchanges 0.4 s apart: each late answer comes long before the next
  o.link.response_timeout_s = 0.03;
  o.link.connect_timeout_s = 10.0;
  T7Device device(o);
  const std::atomic<bool> stop{false};
  ASSERT_TRUE(device.wait_for_reading(10.0, stop)) << device.link_error();
  ASSERT_TRUE(eventually([&] { return device.late_readings() >= 2; }));
  const DeviceHealth h = device.health();
  EXPECT_EQ(h.exchanges, 0u);  // no exchange was answered within its deadline...
  EXPECT_GE(h.link_errors, 2u);
  EXPECT_GE(device.late_readings(), 2u);  // ...and their readings came all the same
  const SensorReading r = device.read_sensors();
  EXPECT_GT(r.time_s, 0.0);
  EXPECT_NEAR(r.supply_bar, PlantParameters{}.supply_bar, 0.05);
  EXPECT_TRUE(device.link_answers());
  EXPECT_EQ(sim.status().exceptions, 0u);
}

// ---- a bounded, interruptible connect ----

TEST(T7Connect, ASlowDeviceEndsTheConnectWithinItsTimeoutNamingTheAddress) {
  T7SimOptions options;
  options.answer_after_s = 1.5;  // each request answered after 1.5 s: ~40 of them would take a minute
  SimThread sim(options);
  T7DeviceOptions o = device_options(sim.port());
  o.link.connect_timeout_s = 2.0;
  const double start = monotonic_seconds();
  try {
    T7Device device(o);
    FAIL() << "configured a T7 that needs a minute for it";
  } catch (const EnvironmentError& error) {
    const std::string what = error.what();
    EXPECT_NE(
        what.find("t7 127.0.0.1:" + std::to_string(sim.port()) + ": no answer within [t7] connect_timeout_s = 2 s"),
        std::string::npos)
        << what;
  }
  EXPECT_LT(monotonic_seconds() - start, 2.0 + 1.0);
}

TEST(T7Connect, AStopSignalEndsTheConnectAtOnce) {
  T7SimOptions options;
  options.answer_after_s = 1.5;
  SimThread sim(options);
  T7DeviceOptions o = device_options(sim.port());
  o.link.connect_timeout_s = 60.0;
  std::atomic<bool> stop{false};
  o.stop = &stop;
  std::thread signal([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    stop.store(true);
  });
  const double start = monotonic_seconds();
  EXPECT_THROW(T7Device{o}, Cancelled);
  EXPECT_LT(monotonic_seconds() - start, 0.5 + 1.0);
  signal.join();
}

}  // namespace
}  // namespace bellows
