// The engine's ticks lock to the phase of a rig's states (devices/tick_phase_lock): a stream of
// states on a clock of its own, read by ticks whose deadlines move by the shifts the lock asks for.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "devices/tick_phase_lock.hpp"
#include "engine/base/errors.hpp"

namespace bellows {
namespace {

constexpr double kPeriod_s = 0.005;

/// A rig publishing every period at `phase_s` (its states arrive then, plus a jitter up to
/// `jitter_s`), read by an engine ticking every period from 0 and shifting its deadlines as the
/// lock asks. Returns the lock after `ticks` ticks; `held` counts the ticks that found no new state.
struct BeatingClocks {
  TickPhaseLock lock;
  double engine_offset_s = 0.0;  // the sum of the shifts taken: the engine's deadlines move by it
  int held = 0;

  void run(double phase_s, double jitter_s, int ticks, unsigned seed = 1) {
    std::mt19937 random(seed);
    std::uniform_real_distribution<double> jitter(0.0, jitter_s);
    int last_state = -1;
    for (int k = 1; k <= ticks; ++k) {
      const double read_s = k * kPeriod_s + engine_offset_s;
      // The newest state handed over by the read: state n arrives at n * period + phase + jitter.
      int newest = static_cast<int>(std::floor((read_s - phase_s) / kPeriod_s));
      double arrived_s = newest * kPeriod_s + phase_s + jitter(random);
      if (arrived_s > read_s) arrived_s = (--newest) * kPeriod_s + phase_s;  // late: the one before is the newest
      if (newest > last_state) {
        lock.observe(read_s - arrived_s);
        last_state = newest;
      } else {
        ++held;
      }
      engine_offset_s += lock.take_shift_s();
    }
  }
};

/// The distance between two leads on the circle of one period.
double circular_distance_s(double a_s, double b_s) {
  const double d = std::fmod(std::abs(a_s - b_s), kPeriod_s);
  return std::min(d, kPeriod_s - d);
}

TEST(TickPhaseLock, StatesArrivingJustBeforeTheReadsMoveTheTicksToHalfAPeriodAfterThem) {
  BeatingClocks clocks{TickPhaseLock({kPeriod_s, 0.5, 1e-4})};
  // The states arrive 0.05 ms before the reads, with 0.3 ms of jitter: without the lock about half
  // the ticks find none new (held).
  BeatingClocks unlocked;
  unlocked.run(kPeriod_s - 0.05e-3, 0.3e-3, 2000);
  EXPECT_GT(unlocked.held, 200) << "the case the lock is for: a phase where jitter holds many ticks";

  clocks.run(kPeriod_s - 0.05e-3, 0.3e-3, 2000);
  EXPECT_NEAR(clocks.lock.lead_s(), 0.5 * kPeriod_s, 0.2e-3);
  EXPECT_LT(clocks.held, 40) << "held only while the lock moved the ticks (2.5 ms at 0.1 ms a tick)";
  // The states arrive 0.15 ms late on average (the jitter's mean): the ticks moved about 2.6 ms.
  EXPECT_LT(circular_distance_s(clocks.lock.shifted_s(), 2.6e-3), 0.25e-3);
}

TEST(TickPhaseLock, ATickIsNeverShiftedByMoreThanItsStep) {
  TickPhaseLock lock({kPeriod_s, 0.5, 1e-4});
  for (int i = 0; i < 100; ++i) {
    lock.observe(0.1e-3);
    const double shift_s = lock.take_shift_s();
    EXPECT_LE(std::abs(shift_s), 1e-4 + 1e-15);
    if (i < 15) {
      EXPECT_EQ(shift_s, 0.0) << "no shift before 16 states agree";
    }
  }
}

TEST(TickPhaseLock, ALeadOnTargetOrLeadsSpreadOverThePeriodAskForNothing) {
  TickPhaseLock on_target({kPeriod_s, 0.5, 1e-4});
  for (int i = 0; i < 100; ++i) {
    on_target.observe(2.5e-3 + (i % 2 == 0 ? 0.05e-3 : -0.05e-3));
    EXPECT_EQ(on_target.take_shift_s(), 0.0);
  }
  TickPhaseLock spread({kPeriod_s, 0.5, 1e-4});
  for (int i = 0; i < 100; ++i) {
    spread.observe((i % 4) * kPeriod_s / 4.0);  // no phase: a shift would chase noise
    EXPECT_EQ(spread.take_shift_s(), 0.0);
  }
}

TEST(TickPhaseLock, LeadsEitherSideOfTheReadAverageOnTheCircle) {
  // 0.1 ms and 4.9 ms after the handover are 0.2 ms apart: their average is at the read, not 2.5 ms.
  TickPhaseLock lock({kPeriod_s, 0.5, 1e-4});
  for (int i = 0; i < 32; ++i) lock.observe(i % 2 == 0 ? 0.1e-3 : 4.9e-3);
  EXPECT_LT(circular_distance_s(lock.lead_s(), 0.0), 0.01e-3);
  EXPECT_NE(lock.take_shift_s(), 0.0);
}

TEST(TickPhaseLock, FollowsARigClockThatDrifts) {
  // A rig on another host: its period 100 ppm longer than the engine's.
  BeatingClocks clocks{TickPhaseLock({kPeriod_s, 0.5, 1e-4})};
  TickPhaseLock& lock = clocks.lock;
  std::mt19937 random(3);
  std::uniform_real_distribution<double> jitter(0.0, 0.3e-3);
  const double rig_period_s = kPeriod_s * (1.0 + 1e-4);
  int last_state = -1;
  int held_late = 0;
  for (int k = 1; k <= 40000; ++k) {  // 200 s: the drift walks the phase round the period 4 times
    const double read_s = k * kPeriod_s + clocks.engine_offset_s;
    int newest = static_cast<int>(std::floor(read_s / rig_period_s));
    double arrived_s = newest * rig_period_s + jitter(random);
    if (arrived_s > read_s) arrived_s = (--newest) * rig_period_s;
    if (newest > last_state) {
      lock.observe(read_s - arrived_s);
      last_state = newest;
    } else if (k > 2000) {
      ++held_late;
    }
    clocks.engine_offset_s += lock.take_shift_s();
  }
  EXPECT_NEAR(lock.lead_s(), 0.5 * kPeriod_s, 0.3e-3);
  // The drift takes one state in 10000 away (the rig is slower): those ticks hold, and nothing else.
  EXPECT_LE(held_late, 5);
}

TEST(TickPhaseLock, ADisabledLockNeverShifts) {
  TickPhaseLock off;  // what an LcmDevice has until set_tick_phase_lock()
  for (int i = 0; i < 100; ++i) {
    off.observe(0.01e-3);
    EXPECT_EQ(off.take_shift_s(), 0.0);
  }
  TickPhaseLock zero_step({kPeriod_s, 0.5, 0.0});  // [lcm] tick_phase_step_s = 0
  for (int i = 0; i < 100; ++i) {
    zero_step.observe(0.01e-3);
    EXPECT_EQ(zero_step.take_shift_s(), 0.0);
  }
}

TEST(TickPhaseLock, RefusesParametersOutsideTheirRanges) {
  EXPECT_THROW(TickPhaseLock({0.0, 0.5, 1e-4}), InputError);
  EXPECT_THROW(TickPhaseLock({kPeriod_s, 0.0, 1e-4}), InputError);
  EXPECT_THROW(TickPhaseLock({kPeriod_s, 1.0, 1e-4}), InputError);
  EXPECT_THROW(TickPhaseLock({kPeriod_s, 0.5, kPeriod_s}), InputError);  // above a tenth of the tick
  EXPECT_NO_THROW(TickPhaseLock({kPeriod_s, 0.5, kPeriod_s / 10.0}));
}

}  // namespace
}  // namespace bellows
