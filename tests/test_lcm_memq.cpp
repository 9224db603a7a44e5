// The LCM protocol in one process over memq://: the rig server (io-sim's core) and the LCM device,
// message by message on one thread with a hand-made clock, then the closed loop on the real-time
// loop; the telemetry publisher over the bus and into an LCM event log.
#include <gtest/gtest.h>

#include <cmath>

#include "bridge/telemetry_publisher.hpp"
#include "devices/lcm_channels.hpp"
#include "devices/lcm_device.hpp"
#include "devices/lcm_rig_server.hpp"
#include "engine/config/configuration.hpp"
#include "engine/rt/engine_core.hpp"
#include "engine/rt/engine_driver.hpp"
#include "engine/base/errors.hpp"
#include "engine/operator/learning_session.hpp"
#include "engine/learning/noilc_dense.hpp"
#include "engine/rt/realtime_loop.hpp"
#include "tests/lcm_bench.hpp"
#include "tests/lcm_test_support.hpp"
#include "tests/process_runner.hpp"

namespace bellows {
namespace {

using testing::BusRecorder;
using testing::decode;
using testing::publish;
using testing::publish_garbage;
using testing::pump;
using testing::Recorded;
using testing::RigBench;
using testing::vented;

constexpr std::int64_t kBinding = 4242;  // the hand-made rig's offer in the device tests

io_state_t state(std::int64_t rig, std::int64_t session, std::int64_t seq, double time_s,
                 std::int64_t command_seq = 0) {
  io_state_t s{};
  s.rig_id = rig;
  s.binding = kBinding;
  s.session_id = session;
  s.seq = seq;
  s.time_s = time_s;
  s.command_seq = command_seq;
  s.angle_rad = 0.01 * static_cast<double>(seq);
  s.chamber_bar[0] = s.chamber_bar[1] = 1.01325;
  s.supply_bar = 3.0;
  s.temperature_K = 293.15;
  return s;
}

TEST(LcmRigServer, HoldsTheSafeStateBindsOneSessionAndVentsWhenCommandsStop) {
  RigBench b;
  const std::int64_t rig = RigBench::kRig;
  const auto command = [&](std::int64_t session, std::int64_t seq, double inlet_a, bool armed, std::int64_t binding) {
    return testing::command(session, seq, inlet_a, armed, rig, binding);
  };
  b.step(0.0);
  EXPECT_TRUE(vented(b.arm.state().command));
  ASSERT_EQ(b.states.size(), 1u);
  io_state_t s = b.last_state();
  EXPECT_EQ(s.rig_id, rig);
  EXPECT_EQ(s.session_id, 0);
  EXPECT_NE(s.binding, 0) << "a free rig offers a binding";
  EXPECT_EQ(s.fault_bits, io_state_t::FAULT_NO_SESSION);
  const std::int64_t offer = s.binding;

  // Nothing invalid, malformed, foreign-typed, addressed elsewhere or armed before binding opens a valve.
  b.send(command(5, 1, 1.5, false, offer));                    // a duty beyond 1
  b.send(testing::command(5, 1, 0.5, false, rig + 1, offer));  // another rig
  b.send(command(5, 1, 0.5, true, offer));                     // armed before binding
  b.send(command(5, 1, 0.5, false, offer + 1));                // a stale offer: a vent, obeyed, binds nothing
  publish_garbage(b.bus, kIoCommandChannel);
  b.step(0.001);
  EXPECT_TRUE(vented(b.arm.state().command));
  EXPECT_EQ(b.rig.stats().serving, 0);

  // The handshake: a vent echoing the offer binds; the session's next commands are applied at once.
  b.send(command(5, 1, 0.0, false, offer));
  b.step(0.001);
  EXPECT_EQ(b.rig.stats().serving, 5);
  EXPECT_TRUE(b.logged("bound to session 5"));
  b.send(command(5, 2, 0.5, true, offer));
  b.step(0.001);
  EXPECT_EQ(b.arm.state().command.inlet_duty[0], 0.5);
  // Another session, an old sequence number, a jump beyond the window: counted, ignored, logged.
  b.send(command(6, 3, 0.9, true, offer));
  b.send(command(5, 2, 0.9, true, offer));
  b.send(command(5, 2 + b.config.lcm.seq_window + 1, 0.9, true, offer));
  b.step(0.001);
  EXPECT_EQ(b.arm.state().command.inlet_duty[0], 0.5);
  EXPECT_TRUE(b.logged("a command of session 6 while serving session 5"));
  EXPECT_TRUE(b.logged("jumping from seq 2 to 103"));
  b.send(command(5, 2 + b.config.lcm.seq_window, 0.4, true, offer));  // the largest step allowed
  b.step(0.003);                                                      // the next state is due
  EXPECT_EQ(b.arm.state().command.inlet_duty[0], 0.4);
  s = b.last_state();
  EXPECT_EQ(s.session_id, 5);
  EXPECT_EQ(s.binding, offer);
  EXPECT_EQ(s.command_seq, 2 + b.config.lcm.seq_window);
  EXPECT_EQ(s.fault_bits, 0);
  EXPECT_EQ(s.foreign_commands, 4) << "the state says what the rig refused: unbound, another session, old, jump";
  EXPECT_GT(s.time_s, 0.0);

  RigServerStats stats = b.rig.stats();
  EXPECT_EQ(stats.commands.accepted, 3u);
  EXPECT_EQ(stats.commands.invalid, 1u);
  EXPECT_EQ(stats.commands.truncated, 1u);
  EXPECT_EQ(stats.commands.wrong_type, 1u);
  EXPECT_EQ(stats.commands.foreign, 2u);  // armed before binding, another session
  EXPECT_EQ(stats.commands.out_of_order, 2u);
  EXPECT_EQ(stats.not_addressed, 1u);

  // Commands stop: within the timeout the rig vents by itself, serves nobody and offers anew.
  for (int i = 0; i < 12; ++i) b.step(0.005);
  EXPECT_TRUE(vented(b.arm.state().command));
  stats = b.rig.stats();
  EXPECT_EQ(stats.timeouts, 1u);
  EXPECT_EQ(stats.serving, 0);
  s = b.last_state();
  EXPECT_EQ(s.session_id, 5) << "the tripped state names the session it dropped (docs/lcm-protocol.md, tripped)";
  EXPECT_NE(s.binding, offer);
  EXPECT_EQ(s.fault_bits, std::int32_t{io_state_t::FAULT_NO_SESSION} | std::int32_t{io_state_t::FAULT_COMMAND_TIMEOUT});

  // The old binding binds nothing any more (a late or replayed command); the new offer does.
  b.send(command(5, 200, 0.0, false, offer));
  b.step(0.001);
  EXPECT_EQ(b.rig.stats().serving, 0);
  b.send(command(6, 1, 0.0, false, s.binding));
  b.send(command(6, 2, 0.3, true, s.binding));
  b.step(0.001);
  EXPECT_EQ(b.rig.stats().serving, 6);
  EXPECT_EQ(b.rig.stats().sessions_served, 2u);
  EXPECT_EQ(b.arm.state().command.inlet_duty[0], 0.3);

  // Its states are published every period, their rig time strictly increasing.
  double last_time = -1.0;
  std::int64_t last_seq = 0;
  for (const Recorded& r : b.states.messages()) {
    const io_state_t each = decode<io_state_t>(r);
    EXPECT_GT(each.time_s, last_time);
    EXPECT_EQ(each.seq, last_seq + 1);
    last_time = each.time_s;
    last_seq = each.seq;
  }
  b.rig.finish(&b.bus, b.t + 0.001);
  EXPECT_TRUE(vented(b.arm.state().command));
}

struct DeviceBench {
  lcm::LCM bus{"memq://"};
  LcmDevice device{1234};
  BusRecorder commands{kIoCommandChannel};
  double t = 10.0;

  DeviceBench() {
    device.attach(bus);
    commands.attach(bus);
  }
  void step(double dt = 0.005) {
    pump(bus);
    t += dt;
    device.service(&bus, t);
    pump(bus);
  }
  io_command_t last_command() { return decode<io_command_t>(commands.messages().back()); }
};

TEST(LcmDevice, SendsACommandForSeveralJointsAsAVent) {
  DeviceBench b;
  ValveCommand two_joints;  // today's messages carry one joint: nothing of this is safe to send
  two_joints.joint_count = 2;
  two_joints.joint[0].inlet_duty = {0.7, 0.0};
  two_joints.joint[1].inlet_duty = {0.0, 0.7};
  b.device.write_valves(two_joints);
  b.step();
  ASSERT_EQ(b.commands.size(), 1u);
  const io_command_t c = b.last_command();
  EXPECT_TRUE(c.armed);
  EXPECT_EQ(c.inlet_duty[0], 0.0);
  EXPECT_EQ(c.inlet_duty[1], 0.0);
  EXPECT_EQ(c.outlet_duty[0], 1.0);
  EXPECT_EQ(c.outlet_duty[1], 1.0);
}

TEST(LcmDevice, TrustsOnlyItsSessionsStatesInOrder) {
  DeviceBench b;
  b.step();
  EXPECT_EQ(b.commands.size(), 0u) << "nothing goes out before the engine's first tick";
  b.device.vent();  // what the engine does every tick in SAFE
  b.step();
  ASSERT_EQ(b.commands.size(), 1u);
  EXPECT_FALSE(b.last_command().armed);
  EXPECT_EQ(b.last_command().seq, 1);

  ValveCommand valves;
  valves.joint[0].inlet_duty = {0.3, 2.0};  // clamped by the device contract
  valves.joint[0].outlet_duty = {std::nan(""), 0.1};
  b.device.write_valves(valves);
  b.step();
  io_command_t c = b.last_command();
  EXPECT_TRUE(c.armed);
  EXPECT_EQ(c.session_id, 1234);
  EXPECT_EQ(c.seq, 2);
  EXPECT_EQ(c.inlet_duty[0], 0.3);
  EXPECT_EQ(c.inlet_duty[1], 1.0);
  EXPECT_EQ(c.outlet_duty[0], 1.0);
  b.step();
  EXPECT_EQ(b.commands.size(), 2u) << "no new valve state from the engine: nothing is sent";
  EXPECT_FALSE(b.device.connected());
  EXPECT_EQ(c.rig_id, 0) << "no rig offered yet: addressed to none";
  b.device.vent();  // offers are taken only while venting
  b.step();

  publish(b.bus, kIoStateChannel, state(55, 999, 1, 0.1));  // another session
  publish(b.bus, kIoStateChannel, state(55, 0, 2, 0.2));    // a rig serving nobody: its offer is taken
  publish_garbage(b.bus, kIoStateChannel);
  b.step();
  EXPECT_FALSE(b.device.connected());
  EXPECT_EQ(b.device.read_sensors().time_s, 0.0);
  b.device.vent();
  b.step();
  EXPECT_EQ(b.last_command().rig_id, 55) << "commands now address the rig that offered";
  EXPECT_EQ(b.last_command().binding, kBinding);

  publish(b.bus, kIoStateChannel, state(55, 1234, 3, 0.3, 2));
  b.step();
  EXPECT_TRUE(b.device.connected());
  SensorReading r = b.device.read_sensors();
  EXPECT_DOUBLE_EQ(r.joint[0].angle_rad, 0.03);
  EXPECT_GT(r.time_s, 0.0);
  const double first_time = r.time_s;
  b.device.write_valves(valves);
  b.step();

  publish(b.bus, kIoStateChannel, state(55, 1234, 3, 0.4, 2));   // repeated sequence number
  publish(b.bus, kIoStateChannel, state(55, 1234, 4, 0.3, 2));   // rig time not advancing
  publish(b.bus, kIoStateChannel, state(55, 1234, 5, 0.5, 99));  // echoes a command never sent
  io_state_t faulty = state(55, 1234, 6, 0.6, 2);
  faulty.fault_bits = io_state_t::FAULT_SENSOR;  // the rig says its sensors are bad
  publish(b.bus, kIoStateChannel, faulty);
  publish(b.bus, kIoStateChannel, state(66, 1234, 1, 0.1, 0));  // another rig while the valves are live
  io_state_t other_binding = state(55, 1234, 7, 0.65, 2);
  other_binding.binding = kBinding + 1;  // not the binding this session made
  publish(b.bus, kIoStateChannel, other_binding);
  b.step();
  EXPECT_EQ(b.device.read_sensors().time_s, first_time) << "none of these is a fresh reading";
  EXPECT_NE(b.device.diagnosis().find("another sender is commanding this rig"), std::string::npos)
      << b.device.diagnosis();

  io_state_t limited = state(55, 1234, 8, 0.7, 2);
  limited.fault_bits = io_state_t::FAULT_PRESSURE_LIMIT;  // a rig limit acting: the reading is still one
  publish(b.bus, kIoStateChannel, limited);
  b.step();
  r = b.device.read_sensors();
  EXPECT_GT(r.time_s, first_time);
  EXPECT_DOUBLE_EQ(r.joint[0].angle_rad, 0.08);

  // Vented, the device follows a restarted rig (new id, a new offer, its sequence from 1) once the
  // old one has been silent for the rig timeout.
  b.device.vent();
  for (int i = 0; i < 12; ++i) b.step();
  EXPECT_FALSE(b.last_command().armed);
  io_state_t offer = state(66, 0, 1, 0.005, 0);
  offer.binding = 99;
  publish(b.bus, kIoStateChannel, offer);
  b.step();
  b.device.vent();
  b.step();
  EXPECT_EQ(b.last_command().rig_id, 66);
  io_state_t served = state(66, 1234, 2, 0.01, 3);
  served.binding = 99;
  publish(b.bus, kIoStateChannel, served);
  b.step();
  EXPECT_DOUBLE_EQ(b.device.read_sensors().joint[0].angle_rad, 0.02);

  const LcmDeviceStats s = b.device.stats();
  EXPECT_EQ(s.rig_id, 66);
  EXPECT_EQ(s.states.accepted, 3u);
  EXPECT_EQ(s.states.foreign, 3u);  // another session, another rig while live, another binding
  EXPECT_EQ(s.states.offers, 2u);   // a free rig's offers are counted apart: not an error
  EXPECT_EQ(s.states.truncated, 1u);
  EXPECT_EQ(s.states.wrong_type, 1u);
  EXPECT_EQ(s.states.out_of_order, 2u);
  EXPECT_EQ(s.states.invalid, 1u);
  EXPECT_EQ(s.commands_not_ours, 1u);
  EXPECT_EQ(s.rig_fault_states, 1u);
  EXPECT_EQ(s.last_foreign_session, 999);

  // Closing leaves the rig vented.
  b.device.write_valves(valves);
  b.step();
  EXPECT_TRUE(b.last_command().armed);
  b.device.finish(&b.bus, b.t + 0.001);
  pump(b.bus);
  EXPECT_FALSE(b.last_command().armed);
}

/// The engine and the LCM device on one thread with a hand-made clock and a hand-made rig.
void expect_stale_fault_after(int stale_ticks) {
  Configuration config;
  config.safety.stale_ticks = stale_ticks;
  DeviceBench b;
  EngineCore core(b.device, config.controller, config.timing, config.safety);
  std::int64_t rig_seq = 1;
  publish(b.bus, kIoStateChannel, state(55, 0, rig_seq, 0.0));  // the rig's offer
  double engine_s = 0.0;
  const auto tick = [&](bool rig_answers) {
    if (rig_answers) {
      ++rig_seq;
      publish(b.bus, kIoStateChannel, state(55, 1234, rig_seq, 0.005 * static_cast<double>(rig_seq)));
    }
    b.step(0.0025);  // the state arrives
    core.tick(engine_s, engine_s, 0);
    engine_s += config.timing.tick_s;
    b.step(0.0025);  // the command leaves
  };
  for (int i = 0; i < 5; ++i) tick(true);
  EngineCommand arm;
  arm.kind = CommandKind::kArm;
  EXPECT_TRUE(core.send(arm));
  for (int i = 0; i < 20; ++i) tick(true);
  ASSERT_EQ(core.state(), EngineState::kArmed);
  EXPECT_TRUE(b.last_command().armed);

  int ticks_without_state = 0;
  while (core.state() != EngineState::kFault && ticks_without_state < 100) {
    tick(false);
    ++ticks_without_state;
  }
  // The rig said nothing at all: the link is lost, and the fault says so (not a sensor's fault).
  EXPECT_EQ(core.fault(), FaultCode::kLinkLost);
  EXPECT_EQ(ticks_without_state, stale_ticks);
  EXPECT_FALSE(b.last_command().armed) << "the fault's vent went out on the bus";
  tick(false);
  EXPECT_FALSE(b.last_command().armed) << "and keeps going out every tick";
}

TEST(LcmDevice, NoStateForStaleTicksIsALostLinkFaultThatVents) {
  expect_stale_fault_after(SafetyParameters{}.stale_ticks);  // the default
  expect_stale_fault_after(6);                               // [safety] stale_ticks
}

Trajectory short_rig_move() {
  return trajectory_from_moves("short", 0.0, {TrapezoidalMove{0.3, 0.0, 20.0, 0.3, 4000.0}}, 1.5, 0.02);
}

std::vector<double> learn_in_process(const Configuration& c, int trials) {
  SimulatedArm arm(c.plant, 3);
  EngineCore core(arm, c.controller, c.timing, c.safety);
  SimulatedClock clock(core, arm);
  const Trajectory trajectory = short_rig_move();
  NormOptimalDense law(discretize_arm_model(c.model, 0.02), c.ilc, trajectory.learning_samples());
  LearningSession session(clock, law, trajectory, c.timing, c.controller);
  std::vector<double> rms;
  for (int i = 0; i < trials; ++i) {
    rms.push_back(session.run_trial().rms_deg);
    session.learn();
  }
  return rms;
}

TEST(LcmClosedLoop, TheEngineDrivesTheRigServerOverMemqAndLearns) {
  Configuration c;
  c.timing.settle_s = 0.3;
  // This test is about learning over the bus on the wall clock. On a loaded 2-core CI machine the
  // I/O thread can be kept off its core for more than the default 3 ticks (15 ms), which the guard
  // rightly calls stale; the stale guard has its own tests above (exact tick counts).
  c.safety.stale_ticks = 40;
  // Likewise the engine's own wake-ups and the rig's command timeout (tested above and in
  // LcmRigFaults): a build beside the suite stalls threads for longer than 5 ticks or 50 ms.
  c.safety.missed_deadline_streak = 1000;
  c.lcm.rig_timeout_s = 1.0;
  SimulatedArm arm(c.plant, 3);
  std::vector<std::string> rig_log;
  RigServer rig(arm, RigBench::parameters(c, LcmKey{}, rig_log), 77);
  LcmDevice device(LcmDevice::random_session_id());
  // Locked to the rig's phase as `--device lcm` runs: unlocked, a run whose states happened to arrive
  // just before the engine's reads holds hundreds of ticks (tick_phase_lock.hpp) and learns slower.
  device.set_tick_phase_lock(TickPhaseLock::Parameters::of(c.timing, c.lcm));
  BusRecorder recorder(kIoStateChannel);
  LcmIoThread io("memq://", {&device, &rig, &recorder});  // memq: one handle, so one thread for both ends
  io.start(RealtimeMode::kTry, 70);
  EngineCore core(device, c.controller, c.timing, c.safety);
  RealtimeLoop loop(core, device, 1.0);
  loop.start(RealtimeMode::kTry);
  ASSERT_TRUE(testing::eventually([&] { return device.connected(); }, 10.0)) << "the rig never answered";

  const Trajectory trajectory = short_rig_move();
  NormOptimalDense law(discretize_arm_model(c.model, 0.02), c.ilc, trajectory.learning_samples());
  LearningSession session(loop, law, trajectory, c.timing, c.controller);
  std::vector<double> rms;
  for (int i = 0; i < 3; ++i) {
    rms.push_back(session.run_trial().rms_deg);
    session.learn();
  }
  loop.stop();
  io.stop();

  const std::vector<double> reference = learn_in_process(c, 3);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(rms[i], reference[i], 0.15 * reference[i]) << "iteration " << i;
  }
  EXPECT_LT(rms[2], rms[0]);
  const LcmDeviceStats d = device.stats();
  const RigServerStats r = rig.stats();
  // Before it served this session the rig's states named nobody: those, and only those, are ignored
  // (how many depends on how soon the binding came, on a loaded machine later: a small part of all).
  EXPECT_EQ(d.states.ignored(), d.states.foreign);
  EXPECT_LT(10u * d.states.foreign, d.states.accepted);
  EXPECT_EQ(r.commands.ignored(), 0u);
  EXPECT_GT(d.states.accepted, 2u * 200u);
  EXPECT_EQ(r.sessions_served, 1u);
  EXPECT_TRUE(vented(arm.state().command)) << "stopping left the rig vented";
}

TEST(LcmClosedLoop, TheEnginesTicksLockToThePhaseOfTheRigsStates) {
  // The rig publishes on its own 5 ms clock, the engine ticks on its own: whatever phase they start
  // with, the lock moves the engine's reads to the share of a period after each state it is asked
  // for. Two targets a half period apart: a lead that was not moved meets both only by chance.
  for (const double lead_fraction : {0.25, 0.75}) {
    Configuration c;
    c.lcm.rig_timeout_s = 1.0;  // a stalled I/O thread on a loaded machine is not what this is about
    SimulatedArm arm(c.plant, 3);
    std::vector<std::string> rig_log;
    RigServer rig(arm, RigBench::parameters(c, LcmKey{}, rig_log), 77);
    LcmDevice device(LcmDevice::random_session_id());
    device.set_tick_phase_lock({c.timing.tick_s, lead_fraction, c.lcm.tick_phase_step_s});
    LcmIoThread io("memq://", {&device, &rig});
    io.start(RealtimeMode::kTry, 70);
    EngineCore core(device, c.controller, c.timing, c.safety);
    RealtimeLoop loop(core, device, 1.0);
    loop.start(RealtimeMode::kTry);  // SAFE: a vent every tick, which binds the rig; its states follow
    ASSERT_TRUE(testing::eventually([&] { return device.connected(); }, 10.0)) << "the rig never answered";
    const double target_ms = 1e3 * lead_fraction * c.timing.tick_s;
    // 2.5 ms at 0.1 ms a tick: 25 ticks; the average lead within 0.6 ms of the target for 10 reads in a row.
    int on_target = 0;
    const bool locked = testing::eventually(
        [&] {
          on_target = std::abs(device.tick_phase_lead_ms() - target_ms) < 0.6 ? on_target + 1 : 0;
          return on_target >= 10;
        },
        20.0);
    loop.stop();
    io.stop();
    EXPECT_TRUE(locked) << "target " << target_ms << " ms, the average lead " << device.tick_phase_lead_ms()
                        << " ms after shifting " << device.tick_phase_shifted_ms() << " ms";
  }
}

// ---- telemetry ----

struct TelemetryRun {
  Configuration config;
  SimulatedArm arm{config.plant, 1};
  EngineCore core{arm, config.controller, config.timing, config.safety};
  TelemetryRing& tap = core.add_telemetry_tap(1 << 14);
  SimulatedClock clock{core, arm};
  Trajectory trajectory = short_rig_move();
  NormOptimalDense law{discretize_arm_model(config.model, 0.02), config.ilc, trajectory.learning_samples()};
  std::vector<IterationSummary> summaries;
  std::vector<Eigen::VectorXd> corrections;

  /// Two trials, a fault, on the simulated clock (the tap holds them all).
  void run(TelemetryPublisher& publisher) {
    LearningSession session(clock, law, trajectory, config.timing, config.controller);
    for (int i = 0; i < 2; ++i) {
      summaries.push_back(session.run_trial());
      corrections.push_back(session.correction_bar());
      publisher.post_trial(summaries.back(), session.correction_bar(), 0.02);
      session.learn();
    }
    EngineCommand stop;
    stop.kind = CommandKind::kEmergencyStop;
    EXPECT_TRUE(core.send(stop));
    clock.step(5);
  }
};

void expect_complete_telemetry(const std::vector<Recorded>& messages, const TelemetryRun& run) {
  std::int64_t next_tick = 0;
  std::vector<std::int8_t> kinds;
  std::vector<std::string> texts;
  std::vector<trial_summary_t> trials;
  for (const Recorded& m : messages) {
    if (m.channel == kTelemetryChannel) {
      const telemetry_t t = decode<telemetry_t>(m);
      EXPECT_EQ(t.tick, next_tick++);
      EXPECT_EQ(t.dropped_ticks, 0);
    } else if (m.channel == kEventChannel) {
      const engine_event_t e = decode<engine_event_t>(m);
      kinds.push_back(e.kind);
      texts.push_back(e.text);
    } else if (m.channel == kTrialChannel) {
      trials.push_back(decode<trial_summary_t>(m));
    } else {
      ADD_FAILURE() << "unexpected channel " << m.channel;
    }
  }
  EXPECT_EQ(next_tick, static_cast<std::int64_t>(run.core.ticks())) << "one telemetry message per tick";
  // SAFE -> ARMED; per trial: ARMED -> RUNNING, started, ended, RUNNING -> ARMED; then the fault.
  using E = engine_event_t;
  const std::vector<std::int8_t> expected = {E::KIND_STATE_CHANGED, E::KIND_STATE_CHANGED, E::KIND_TRIAL_STARTED,
                                             E::KIND_TRIAL_ENDED,   E::KIND_STATE_CHANGED, E::KIND_STATE_CHANGED,
                                             E::KIND_TRIAL_STARTED, E::KIND_TRIAL_ENDED,   E::KIND_STATE_CHANGED,
                                             E::KIND_STATE_CHANGED, E::KIND_FAULT};
  EXPECT_EQ(kinds, expected);
  ASSERT_FALSE(texts.empty());
  EXPECT_EQ(texts.front(), "SAFE -> ARMED");
  EXPECT_EQ(texts.back(), "emergency-stop: emergency stop requested by the operator");
  ASSERT_EQ(trials.size(), 2u);
  for (int i = 0; i < 2; ++i) {
    EXPECT_EQ(trials[i].iteration, i);
    EXPECT_EQ(trials[i].rms_deg, run.summaries[i].rms_deg);
    ASSERT_EQ(trials[i].correction_bar.size(), static_cast<std::size_t>(run.trajectory.learning_samples()));
    EXPECT_EQ(trials[i].correction_bar.back(), run.corrections[i](run.trajectory.learning_samples() - 1));
  }
}

TEST(LcmTelemetry, EveryTickEveryEventAndEveryTrialReachTheBus) {
  TelemetryRun run;
  TelemetryPublisher publisher(run.tap, 42, nullptr);
  lcm::LCM bus("memq://");
  BusRecorder recorder;
  recorder.attach(bus);
  run.run(publisher);
  publisher.service(&bus, 1.0);
  publisher.finish(&bus, 1.1);
  pump(bus);
  expect_complete_telemetry(recorder.messages(), run);
  const TelemetryPublisherStats s = publisher.stats();
  EXPECT_EQ(s.ticks, run.core.ticks());
  EXPECT_EQ(s.trials, 2u);
  EXPECT_EQ(s.errors, 0u);
}

TEST(LcmTelemetry, TheEventLogHoldsEveryMessageInLcmsFormat) {
  const auto dir = testing::make_temp_dir("bellows-lcm-log");
  const std::string path = (dir / "run.lcmlog").string();
  TelemetryRun run;
  {
    std::FILE* stream = std::fopen(path.c_str(), "wb");  // bellows run gives the safe writer's (app/run_io)
    ASSERT_NE(stream, nullptr);
    TelemetryPublisher publisher(run.tap, 42, stream);
    run.run(publisher);
    publisher.finish(nullptr, 0.0);  // no bus: the log only
    EXPECT_EQ(publisher.stats().log_events, publisher.stats().ticks + publisher.stats().events + 2);
    EXPECT_EQ(std::fclose(stream), 0);
  }
  lcm::LogFile log(path, "r");
  ASSERT_TRUE(log.good());
  std::vector<Recorded> messages;
  std::int64_t last_timestamp = 0;
  for (const lcm::LogEvent* e = log.readNextEvent(); e != nullptr; e = log.readNextEvent()) {
    EXPECT_GE(e->timestamp, last_timestamp);
    last_timestamp = e->timestamp;
    const auto* data = static_cast<const std::uint8_t*>(e->data);
    messages.push_back({e->channel, std::vector<std::uint8_t>(data, data + e->datalen), 0.0});
  }
  expect_complete_telemetry(messages, run);
  // An existing log is never overwritten: LcmCli.RefusesWhatMakesNoSenseAndSaysWhenNoRigAnswers and the
  // --lcm-log legs of test_save_faults (the safe writer, killed and failed at every call).
}

}  // namespace
}  // namespace bellows
