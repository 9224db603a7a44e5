// Locks the engine's ticks to the phase of a rig that publishes its states on a clock of its own
// (an LCM rig, docs/lcm-protocol.md "Timing"). Two free-running clocks of the same period keep
// whatever phase they started with (on one host exactly; across hosts it drifts by their ppm). When
// the states reach the engine just before its reads, every wake-up jitter either way turns a tick
// into one without a new state (held, valves closed) and the next into one with two: measured on
// this 2-core VM, 550 held ticks in a 3-iteration run whose states arrived 0.05 ms before the reads,
// against 0-30 in runs whose phase was not so. The lock measures, for each fresh state, how long
// after it was handed over the engine read it (its lead), averages the leads on the circle (a lead
// of 0.1 ms and one of 4.9 ms are 0.2 ms apart, not 4.8) and asks the loop to start its next tick a
// little later or earlier, at most `step_s` per tick, until the states are read `lead_fraction` of a
// period after they arrive: half a period leaves the most room for jitter either way. The engine
// ticks at its own pace as before; only the phase of its deadlines moves, in steps far below the
// wake-up jitter. Plain arithmetic, no allocation: the engine thread calls it on every tick.
#pragma once

#include "engine/base/parameters.hpp"

namespace bellows {

class TickPhaseLock {
 public:
  struct Parameters {
    double period_s = 0.005;     // the engine's tick and the rig's state period ([timing] tick_s)
    double lead_fraction = 0.5;  // read each state this share of a period after it arrives ([lcm] tick_phase_lead)
    double step_s = 1e-4;        // largest shift of one tick's deadline ([lcm] tick_phase_step_s); 0: no lock

    /// The lock a wall-clock LCM rig gets from the configuration (what `--device lcm` runs with).
    static Parameters of(const TimingParameters& timing, const LcmParameters& lcm) {
      return {timing.tick_s, lcm.tick_phase_lead, lcm.tick_phase_step_s};
    }
  };

  /// A lock that never shifts (step 0).
  TickPhaseLock() { parameters_.step_s = 0.0; }
  /// InputError unless period_s > 0, lead_fraction in (0, 1) and step_s in [0, period_s / 10].
  explicit TickPhaseLock(const Parameters& parameters);

  /// A fresh state was read `lead_s` after it was handed over to the engine (>= 0).
  void observe(double lead_s);
  /// How much later (s; negative: earlier) the next tick should start than one period after this
  /// one; the estimate moves with the shift it asks for. 0 until enough leads agree on a phase.
  double take_shift_s();

  /// The average lead (s, in [0, period)), or -1 before any state.
  double lead_s() const;
  /// The sum of every shift asked for (s).
  double shifted_s() const { return shifted_s_; }
  const Parameters& parameters() const { return parameters_; }

 private:
  Parameters parameters_{};
  double cos_ = 0.0, sin_ = 0.0;  // the leads' average on the unit circle (one period = one turn)
  int observed_ = 0;
  double shifted_s_ = 0.0;
};

}  // namespace bellows
