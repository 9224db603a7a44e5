#include "devices/tick_phase_lock.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "engine/base/errors.hpp"

namespace bellows {
namespace {
// The leads are averaged over about this many states (80 ms at 200 Hz): long against the wake-up
// jitter of one tick, short against the settling before a trial.
constexpr int kAveragedStates = 16;
// Leads spread this evenly around the period (|average| on the unit circle below it) have no phase
// to lock to: the jitter is as large as the period, and a shift would chase noise.
constexpr double kLeastCoherence = 0.5;

constexpr double kTurn = 2.0 * std::numbers::pi;
}  // namespace

TickPhaseLock::TickPhaseLock(const Parameters& parameters) : parameters_(parameters) {
  if (!(parameters_.period_s > 0.0)) throw InputError("the tick phase lock needs a positive period");
  if (!(parameters_.lead_fraction > 0.0 && parameters_.lead_fraction < 1.0)) {
    throw InputError("[lcm] tick_phase_lead must be above 0 and below 1 (a share of the tick)");
  }
  if (!(parameters_.step_s >= 0.0 && parameters_.step_s <= parameters_.period_s / 10.0)) {
    throw InputError("[lcm] tick_phase_step_s must be between 0 and a tenth of [timing] tick_s");
  }
}

void TickPhaseLock::observe(double lead_s) {
  if (!(lead_s >= 0.0) || !std::isfinite(lead_s)) return;
  const double angle = kTurn * std::fmod(lead_s, parameters_.period_s) / parameters_.period_s;
  observed_ = std::min(observed_ + 1, kAveragedStates);
  const double weight = 1.0 / observed_;  // the plain mean until kAveragedStates, then exponential
  cos_ += weight * (std::cos(angle) - cos_);
  sin_ += weight * (std::sin(angle) - sin_);
}

double TickPhaseLock::lead_s() const {
  if (observed_ == 0) return -1.0;
  double turns = std::atan2(sin_, cos_) / kTurn;
  if (turns < 0.0) turns += 1.0;
  return turns * parameters_.period_s;
}

double TickPhaseLock::take_shift_s() {
  const double step_s = parameters_.step_s;
  if (step_s <= 0.0 || observed_ < kAveragedStates || std::hypot(cos_, sin_) < kLeastCoherence) return 0.0;
  const double period_s = parameters_.period_s;
  // How far the average lead is from the target, the short way round: in [-period/2, period/2).
  double error_s = lead_s() - parameters_.lead_fraction * period_s;
  error_s -= period_s * std::floor(error_s / period_s + 0.5);
  if (std::abs(error_s) <= step_s) return 0.0;
  const double shift_s = std::clamp(-error_s, -step_s, step_s);  // reading later lengthens every lead
  const double turn = kTurn * shift_s / period_s;
  const double c = cos_ * std::cos(turn) - sin_ * std::sin(turn);
  sin_ = cos_ * std::sin(turn) + sin_ * std::cos(turn);
  cos_ = c;
  shifted_s_ += shift_s;
  return shift_s;
}

}  // namespace bellows
