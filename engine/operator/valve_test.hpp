// The valve test of the first day at the bench (`bellows rig check`, the console's Rig screen).
//
// Each valve (inlet A, inlet B, outlet A, outlet B) is opened alone for `[rig_check] valve_pulse_s`
// and the chamber pressures before and after are compared: its own chamber must move the right way
// (an inlet fills, an outlet lets out) clearly more than the other one, counted as air (pressure
// at the nominal volume), since the turning arm squeezes one chamber and lets the other grow. Before each valve both
// outlets vent the chambers to ambient; before an outlet both inlets first put some air in.
// Each step ends with every valve closed for the link's lag (the round trip to the rig) and its
// reading is the first fresh one after that: on a rig whose readings lag its commands (LCM), a
// chamber still filling is never mistaken for one that did not fall. The judge takes only a
// reading taken after the one before the pulse.
// Everything goes through the engine (kValvePulse while ARMED), so the guards and the emergency stop
// apply as in any trial. A valve that fails is named with the likely problem: swapped tubes or
// wires, a dead valve, no supply. A valve that moved nothing is vented and pulsed again
// ([rig_check] valve_pulse_attempts) before it is called dead: a link or a host that held one
// pulse's command back (a T7 answering late, a vCPU not run for 100 ms) is not a dead valve.
//
// ValveTest is a step machine for an operator thread that owns the engine's event queue (the
// console forwards its events); run_valve_test() drives it to the end on its own (headless).
// It tests joint 0's valves (an arm of one joint; the other joints' valves stay closed).
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include "engine/rt/engine_driver.hpp"
#include "engine/rt/engine_messages.hpp"
#include "engine/base/parameters.hpp"
#include "engine/control/safety.hpp"

namespace bellows {

enum class ValveId : std::uint8_t { kInletA, kInletB, kOutletA, kOutletB };
inline constexpr int kValveCount = 4;

/// "inlet A", "inlet B", "outlet A", "outlet B".
const char* valve_name(ValveId valve);

struct ValveVerdict {
  ValveId valve = ValveId::kInletA;
  bool tested = false;
  bool pass = false;
  double own_change_bar = 0.0;    // its own chamber's change over the pulse
  double other_change_bar = 0.0;  // the other chamber's
  std::string problem;            // why it failed (empty when it passed)
  // Nothing moved (a dead valve, no fresh reading, no air to let out): what a link or a host that
  // held the pulse's command back also shows, so such a verdict is tried again ([rig_check]
  // valve_pulse_attempts).
  bool moved_nothing = false;
  int pulses = 0;  // how many pulses the verdict took (more than one: the ones before moved nothing)
};

/// "" for a verdict of one pulse; else " (pulse 2 of 2: the one before moved nothing)", for its line.
std::string repeat_note(const ValveVerdict& verdict);

struct ValveTestReport {
  std::array<ValveVerdict, kValveCount> valves{};
  bool finished = false;
  std::string aborted;  // not empty: the test stopped early (a fault, a refusal), and why
  bool all_pass() const;
  /// One line per failed valve: "inlet A: dead valve: ...".
  std::vector<std::string> failure_lines() const;
};

/// Judges one valve from the readings before and after its pulse (pure; the rules above; `pulses`
/// left 0 for the caller). The
/// chambers are compared by their air, p (1 +- beta alpha) with beta = `volume_gain_per_rad`
/// ([model] volume_gain): a closed chamber the turning arm squeezes keeps its air.
ValveVerdict judge_valve(ValveId valve, const SensorReading& before, const SensorReading& after, double ambient_bar,
                         const RigCheckParameters& check, double supply_min_bar, double volume_gain_per_rad);

class ValveTest {
 public:
  /// `link_lag_s`: how long after a command a reading shows it (the device's round trip p99; 0 in process).
  ValveTest(const RigCheckParameters& check, const SafetyParameters& safety, double ambient_bar, double tick_s,
            double volume_gain_per_rad, double link_lag_s = 0.0);

  /// The commands that start the test, given the engine's state and a recent reading. With no
  /// supply (below [safety] supply_min_bar) nothing is armed: the test ends at once, every valve
  /// failed and named. Only from SAFE or ARMED.
  std::vector<EngineCommand> begin(EngineState state, const SensorReading& latest);
  /// Every engine event while the test runs; returns what to send next.
  std::vector<EngineCommand> on_event(const EngineEvent& event);
  /// Stops early (the operator's emergency stop, a signal): remaining valves are not tested.
  void abandon(const std::string& why);

  bool running() const { return started_ && !report_.finished; }
  const ValveTestReport& report() const { return report_; }
  /// What it is doing, for the operator: "inlet B: venting (2 of 4)".
  std::string progress() const;

 private:
  enum class Step : std::uint8_t { kVent, kFill, kPulse };
  EngineCommand command_for(Step step);
  std::vector<EngineCommand> next_step();
  void finish_with(const std::string& why);

  RigCheckParameters check_;
  SafetyParameters safety_;
  double ambient_bar_;
  double tick_s_;
  double volume_gain_per_rad_;
  int settle_ticks_ = 0;  // the link's lag in ticks
  bool started_ = false;
  int valve_ = 0;
  int attempt_ = 0;  // the valve's pulses so far that moved nothing
  Step step_ = Step::kVent;
  std::uint32_t pulse_id_ = 0;
  SensorReading before_{};
  ValveTestReport report_;
};

/// Runs the whole test through `driver` (its own event consumer), then disarms. `stop`, when set,
/// emergency-stops and ends the test early.
ValveTestReport run_valve_test(EngineDriver& driver, const RigCheckParameters& check, const SafetyParameters& safety,
                               double ambient_bar, double volume_gain_per_rad, const std::atomic<bool>* stop = nullptr,
                               double link_lag_s = 0.0);

}  // namespace bellows
